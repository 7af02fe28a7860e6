//! What every component process shares: bus options, the session, `info`, replies.
//!
//! What: [`ComponentArgs`] (the command-line options of every component:
//! `--namespace`, `--connect`, `--listen`, `--mode`, `--zenoh-config`) and
//! [`Component`] (an open session that answers `<ns>/<name>/info` with the
//! component's name, version and keys, and declares the component's queryables and
//! publishers so they are listed there).
//!
//! Why: the vision and controller processes (and the test mocks) join the bus the
//! same way as the host — loopback only, no scouting, zenoh's reassembly buffer
//! capped for the same payload limit as the host's, a zenoh config file replaces
//! all of it — and a client can see what is on the bus by asking `<ns>/*/info`.
//!
//! How: a thin layer over one `zenoh::Session`. Queryables get a plain callback; a
//! component whose answer takes time moves the `Query` to its own thread and replies
//! from there ([`Component::serve_query`]).
//!
//! ```
//! use clap::Parser;
//! #[derive(Parser)]
//! struct Cli {
//!     #[command(flatten)]
//!     bus: tsukami_bus::ComponentArgs,
//! }
//! let cli = Cli::parse_from(["x", "--namespace", "robot2", "--connect", "tcp/127.0.0.1:7000"]);
//! assert_eq!(cli.bus.keys().component_info("controller"), "robot2/controller/info");
//! assert_eq!(cli.bus.bus_config().connect, ["tcp/127.0.0.1:7000"]);
//! // Without --connect a component connects to the default host.
//! let cli = Cli::parse_from(["x"]);
//! assert_eq!(cli.bus.bus_config().connect, [tsukami_bus::default_endpoint()]);
//! ```

use crate::config::{default_endpoint, BusConfig, BusMode};
use crate::serve::{parse_query, reply_error, reply_json, reply_json_on};
use anyhow::{anyhow, Result};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use tsukami_msgs::component::ComponentInfo;
use tsukami_msgs::keys::DEFAULT_NAMESPACE;
use tsukami_msgs::{ErrorReply, KeySpace};
use zenoh::pubsub::Publisher;
use zenoh::query::{Query, Queryable};
use zenoh::Wait;

/// How a component joins the bus (flatten into the component's clap parser).
#[derive(clap::Args, Debug, Clone)]
pub struct ComponentArgs {
    /// Key-expression namespace (the host's).
    #[arg(long, default_value = DEFAULT_NAMESPACE)]
    pub namespace: String,
    /// Endpoint to connect to, repeatable (loopback only without --zenoh-config);
    /// default: the default host, tcp/127.0.0.1:17447.
    #[arg(long)]
    pub connect: Vec<String>,
    /// Endpoint to listen on, repeatable (loopback only without --zenoh-config), so
    /// peers can connect to this component directly.
    #[arg(long)]
    pub listen: Vec<String>,
    /// zenoh mode: `peer`, or `client` to talk only through the router or peer
    /// connected to (ignored with --zenoh-config).
    #[arg(long, value_enum, default_value_t = BusMode::Peer)]
    pub mode: BusMode,
    /// A zenoh json5 config file; replaces the built-in loopback-only config.
    #[arg(long)]
    pub zenoh_config: Option<PathBuf>,
}

impl ComponentArgs {
    /// Options for a component under `namespace` connecting to `endpoint`.
    pub fn connecting(namespace: &str, endpoint: &str) -> ComponentArgs {
        ComponentArgs {
            namespace: namespace.to_owned(),
            connect: vec![endpoint.to_owned()],
            listen: vec![],
            mode: BusMode::Peer,
            zenoh_config: None,
        }
    }

    /// The bus config these options describe.
    pub fn bus_config(&self) -> BusConfig {
        let connect = if self.connect.is_empty() && self.listen.is_empty() {
            vec![default_endpoint()]
        } else {
            self.connect.clone()
        };
        BusConfig {
            listen: self.listen.clone(),
            connect,
            zenoh_config: self.zenoh_config.clone(),
            mode: self.mode,
        }
    }

    /// The key space of the namespace.
    pub fn keys(&self) -> KeySpace {
        KeySpace::new(&self.namespace)
    }
}

/// A component on the bus: its session, and its `<ns>/<name>/info` answer.
pub struct Component {
    session: zenoh::Session,
    keys: KeySpace,
    info: Arc<Mutex<ComponentInfo>>,
    info_queryable: Option<Queryable<()>>,
}

impl Component {
    /// Joins the bus as `args` say and starts answering `<ns>/<name>/info`.
    pub fn start(
        name: &str,
        version: &str,
        description: &str,
        args: &ComponentArgs,
    ) -> Result<Component> {
        let session = args
            .bus_config()
            .open_bounded(crate::serve::MAX_PAYLOAD_BYTES)?;
        Component::on_session(session, &args.namespace, name, version, description)
    }

    /// Like [`Component::start`], on a session that is already open.
    pub fn on_session(
        session: zenoh::Session,
        namespace: &str,
        name: &str,
        version: &str,
        description: &str,
    ) -> Result<Component> {
        let keys = KeySpace::new(namespace);
        let info_key = keys.component_info(name);
        let info = Arc::new(Mutex::new(ComponentInfo {
            name: name.to_owned(),
            version: version.to_owned(),
            description: description.to_owned(),
            namespace: keys.namespace().to_owned(),
            keys: vec![info_key.clone()],
        }));
        let shared = info.clone();
        let reply_key = info_key.clone();
        let queryable = session
            .declare_queryable(&info_key)
            .callback(move |query| {
                let info = shared.lock().unwrap_or_else(|e| e.into_inner()).clone();
                // On its own key: a `<ns>/*/info` query then gets one reply per
                // component (zenoh consolidates replies on the same key).
                reply_json_on(&query, &reply_key, &info);
            })
            .wait()
            .map_err(|e| anyhow!("declaring {info_key}: {e}"))?;
        tracing::info!(component = name, version, namespace, "on the bus");
        Ok(Component {
            session,
            keys,
            info,
            info_queryable: Some(queryable),
        })
    }

    /// The zenoh session.
    pub fn session(&self) -> &zenoh::Session {
        &self.session
    }

    /// The key space.
    pub fn keys(&self) -> &KeySpace {
        &self.keys
    }

    /// What `<ns>/<name>/info` answers.
    pub fn info(&self) -> ComponentInfo {
        self.info.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    fn list_key(&self, key: &str) {
        let mut info = self.info.lock().unwrap_or_else(|e| e.into_inner());
        if !info.keys.iter().any(|k| k == key) {
            info.keys.push(key.to_owned());
        }
    }

    /// Answers `key` with `handler`, called in zenoh's callback (keep it quick): the
    /// request is checked and parsed first ([`parse_query`]); `Ok` is sent as JSON,
    /// `Err` as the error reply.
    pub fn serve<Req, Rep, F>(&self, key: &str, handler: F) -> Result<Queryable<()>>
    where
        Req: DeserializeOwned,
        Rep: Serialize,
        F: Fn(Req) -> Result<Rep, ErrorReply> + Send + Sync + 'static,
    {
        self.serve_query(key, move |query| match parse_query::<Req>(&query) {
            Ok(request) => match handler(request) {
                Ok(reply) => reply_json(&query, &reply),
                Err(error) => reply_error(&query, error),
            },
            Err(error) => reply_error(&query, error),
        })
    }

    /// Hands every query on `key` to `callback`, which may keep the `Query` and
    /// reply later from another thread (zenoh sends the reply when it is dropped).
    ///
    /// The queryable is declared complete. Tsukami's callers send to every
    /// matching queryable ([`crate::client::query`]): the host's fallback
    /// `<ns>/*/stop` (`no_plugin` for absent roles) gets the query too and stands
    /// aside, and a second process declaring `key` is `conflicting_responders`.
    pub fn serve_query<F>(&self, key: &str, callback: F) -> Result<Queryable<()>>
    where
        F: Fn(Query) + Send + Sync + 'static,
    {
        let queryable = self
            .session
            .declare_queryable(key.to_owned())
            .complete(true)
            .callback(callback)
            .wait()
            .map_err(|e| anyhow!("declaring {key}: {e}"))?;
        self.list_key(key);
        Ok(queryable)
    }

    /// A publisher on `key`, listed in `info`.
    pub fn publisher(&self, key: &str) -> Result<Publisher<'static>> {
        let publisher = self
            .session
            .declare_publisher(key.to_owned())
            .encoding(zenoh::bytes::Encoding::APPLICATION_JSON)
            .wait()
            .map_err(|e| anyhow!("declaring publisher {key}: {e}"))?;
        self.list_key(key);
        Ok(publisher)
    }

    /// Leaves the bus: stops answering `info` and closes the session (every
    /// queryable and publisher of the session goes with it).
    pub fn close(mut self) {
        drop(self.info_queryable.take());
        if let Err(e) = self.session.close().wait() {
            tracing::warn!("closing the zenoh session: {e}");
        }
    }
}
