//! The built-in zenoh configuration: loopback only, no scouting.
//!
//! What: [`BusConfig`] (how a process joins the bus), the endpoint check, and a free
//! loopback port for private buses.
//!
//! Why: zenoh, left to its defaults, listens on every interface (`tcp/[::]:0`) and
//! scouts by UDP multicast to 224.0.0.224. Tsukami's defaults send nothing beyond
//! loopback: peer mode, multicast and gossip scouting off, listen and connect on
//! `tcp/127.0.0.1` only. A user who wants several machines hands in a zenoh json5
//! config file, which replaces these defaults entirely (routers, TLS, access control
//! are zenoh's business, not ours).
//!
//! How: [`BusConfig::to_zenoh`] writes `mode`, `listen`, `connect` and the scouting
//! switches into a default zenoh config after checking every endpoint.
//!
//! ```
//! use tsukami_bus::{BusConfig, BusMode};
//! let bus = BusConfig::connecting("tcp/127.0.0.1:17447");
//! assert_eq!(bus.mode, BusMode::Peer);
//! assert!(bus.to_zenoh().is_ok());
//! assert!(BusConfig::connecting("tcp/192.168.1.2:7447").to_zenoh().is_err());
//! ```

use anyhow::{bail, Context, Result};
use std::path::PathBuf;

/// The loopback port the default host config listens on (see the README).
pub const DEFAULT_PORT: u16 = 17447;

/// The loopback port `tsukami router` listens on by default (zenoh's usual router port).
pub const DEFAULT_ROUTER_PORT: u16 = 7447;

/// The loopback endpoint of the default host.
pub fn default_endpoint() -> String {
    format!("tcp/127.0.0.1:{DEFAULT_PORT}")
}

/// zenoh's role for this process. `peer` is the default: processes talk directly.
/// `router` forwards for everyone connected to it (`tsukami router`); `client`
/// talks only through the router or peer it connects to.
#[derive(
    Debug,
    Clone,
    Copy,
    Default,
    PartialEq,
    Eq,
    serde::Deserialize,
    serde::Serialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "snake_case")]
pub enum BusMode {
    /// Talk directly to the processes connected to.
    #[default]
    Peer,
    /// Talk only through the router or peer connected to.
    Client,
    /// Forward between everyone connected.
    Router,
}

impl BusMode {
    /// zenoh's name of the mode.
    pub fn as_str(self) -> &'static str {
        match self {
            BusMode::Peer => "peer",
            BusMode::Client => "client",
            BusMode::Router => "router",
        }
    }
}

/// How to join the bus.
#[derive(Debug, Clone, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct BusConfig {
    /// Endpoints to listen on; must be loopback (`tcp/127.0.0.1:PORT`) unless
    /// `zenoh_config` is given.
    #[serde(default)]
    pub listen: Vec<String>,
    /// Endpoints to connect to; loopback likewise.
    #[serde(default)]
    pub connect: Vec<String>,
    /// A zenoh json5 config file that replaces every default above.
    #[serde(default)]
    pub zenoh_config: Option<PathBuf>,
    /// zenoh mode (default `peer`); ignored when `zenoh_config` is given.
    #[serde(default, skip_serializing_if = "is_peer")]
    pub mode: BusMode,
}

fn is_peer(mode: &BusMode) -> bool {
    *mode == BusMode::Peer
}

impl BusConfig {
    /// A host listening on `endpoint`.
    pub fn listening(endpoint: &str) -> Self {
        BusConfig {
            listen: vec![endpoint.to_owned()],
            connect: vec![],
            zenoh_config: None,
            mode: BusMode::Peer,
        }
    }

    /// A client connecting to `endpoint` (listening nowhere).
    pub fn connecting(endpoint: &str) -> Self {
        BusConfig {
            listen: vec![],
            connect: vec![endpoint.to_owned()],
            zenoh_config: None,
            mode: BusMode::Peer,
        }
    }

    /// A zenoh router listening on `endpoint`: the processes connect to it (in
    /// `client` mode) instead of to each other.
    pub fn router(endpoint: &str) -> Self {
        BusConfig {
            listen: vec![endpoint.to_owned()],
            connect: vec![],
            zenoh_config: None,
            mode: BusMode::Router,
        }
    }

    /// Builds the zenoh config.
    pub fn to_zenoh(&self) -> Result<zenoh::Config> {
        if let Some(path) = &self.zenoh_config {
            return zenoh::Config::from_file(path)
                .map_err(|e| anyhow::anyhow!("{e}"))
                .with_context(|| format!("reading zenoh config {}", path.display()));
        }
        for endpoint in self.listen.iter().chain(&self.connect) {
            check_loopback(endpoint)?;
        }
        let mut config = zenoh::Config::default();
        let set = |config: &mut zenoh::Config, key: &str, value: String| {
            config
                .insert_json5(key, &value)
                .map_err(|e| anyhow::anyhow!("zenoh config `{key}` = {value}: {e}"))
        };
        set(&mut config, "mode", format!("\"{}\"", self.mode.as_str()))?;
        set(
            &mut config,
            "listen/endpoints",
            serde_json::to_string(&self.listen)?,
        )?;
        set(
            &mut config,
            "connect/endpoints",
            serde_json::to_string(&self.connect)?,
        )?;
        set(&mut config, "scouting/multicast/enabled", "false".into())?;
        set(&mut config, "scouting/gossip/enabled", "false".into())?;
        Ok(config)
    }

    /// Opens a zenoh session with this config, zenoh's reassembly buffer capped
    /// at [`reassembly_cap`]`(max_payload_bytes)` (zenoh's default is 1 GiB, so one
    /// oversized request could grow the process by that much before it is
    /// refused). A user's zenoh config file sets its own
    /// (`transport/link/rx/max_message_size`) and is used as it is.
    pub fn open_bounded(&self, max_payload_bytes: usize) -> Result<zenoh::Session> {
        use zenoh::Wait;
        if self.zenoh_config.is_some() {
            return self.open();
        }
        let mut config = self.to_zenoh()?;
        let cap = reassembly_cap(max_payload_bytes);
        config
            .insert_json5("transport/link/rx/max_message_size", &cap.to_string())
            .map_err(|e| anyhow::anyhow!("zenoh rx max_message_size: {e}"))?;
        zenoh::open(config)
            .wait()
            .map_err(|e| anyhow::anyhow!("opening the zenoh session ({}): {e}", self.describe()))
    }

    /// Opens a zenoh session with this config.
    pub fn open(&self) -> Result<zenoh::Session> {
        use zenoh::Wait;
        let config = self.to_zenoh()?;
        zenoh::open(config)
            .wait()
            .map_err(|e| anyhow::anyhow!("opening the zenoh session ({}): {e}", self.describe()))
    }

    fn describe(&self) -> String {
        match &self.zenoh_config {
            Some(path) => format!("zenoh config {}", path.display()),
            None => format!(
                "{} mode, listen {:?}, connect {:?}",
                self.mode.as_str(),
                self.listen,
                self.connect
            ),
        }
    }
}

/// The largest message zenoh reassembles for a process that accepts payloads of up
/// to `max_payload_bytes`: twice that plus 1 MiB, so every payload up to twice the
/// limit is still answered `payload_too_large`; a larger message is dropped by
/// zenoh's receiving transport (no reply; the link stays up). See
/// docs/protocol.md, "Payloads over zenoh's reassembly cap".
pub fn reassembly_cap(max_payload_bytes: usize) -> usize {
    max_payload_bytes.saturating_mul(2).saturating_add(1 << 20)
}

/// Refuses endpoints that would leave the machine: the built-in config is loopback
/// only. (A zenoh config file is the way to reach other machines.)
pub fn check_loopback(endpoint: &str) -> Result<()> {
    let Some(address) = endpoint.strip_prefix("tcp/") else {
        bail!(
            "endpoint `{endpoint}`: only tcp/127.0.0.1:PORT is allowed without a zenoh config file"
        );
    };
    let host = address.rsplit_once(':').map(|(h, _)| h).unwrap_or(address);
    if host != "127.0.0.1" && host != "localhost" && host != "[::1]" {
        bail!("endpoint `{endpoint}` is not loopback; use a zenoh config file (--zenoh-config) to reach other machines");
    }
    Ok(())
}

/// A free TCP port on 127.0.0.1, for private hosts (tests, the demo). zenoh cannot
/// report the port it picked for `:0` without its unstable API, so we pick one.
pub fn free_loopback_port() -> Result<u16> {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").context("binding 127.0.0.1:0")?;
    Ok(listener.local_addr()?.port())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_loopback_without_scouting() {
        let config = BusConfig::listening("tcp/127.0.0.1:7000")
            .to_zenoh()
            .unwrap();
        let text = format!("{config}");
        assert!(text.contains("127.0.0.1:7000"), "{text}");
        let multicast = config.get_json("scouting/multicast/enabled").unwrap();
        assert_eq!(multicast, "false");
        let gossip = config.get_json("scouting/gossip/enabled").unwrap();
        assert_eq!(gossip, "false");
    }

    #[test]
    fn non_loopback_endpoints_are_refused() {
        assert!(check_loopback("tcp/127.0.0.1:1").is_ok());
        assert!(check_loopback("tcp/0.0.0.0:1").is_err());
        assert!(check_loopback("tcp/[::]:1").is_err());
        assert!(check_loopback("udp/127.0.0.1:1").is_err());
        assert!(BusConfig::connecting("tcp/10.0.0.1:7447")
            .to_zenoh()
            .is_err());
    }
}
