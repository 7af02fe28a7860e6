//! The result viewer as the `result-viewer` plugin (`<ns>/viewer/*`).
//!
//! What: [`ViewerPlugin`] shares the host's world (the kit's session, the
//! `world` capability), follows the bus ([`crate::follow`]), serves the live
//! web view ([`crate::web`]) and answers `render` (a PNG of the latest plan,
//! base64), `glb` (the same scene as glTF 2.0 binary, base64) and `state`
//! (what it shows, the page's address); `world_prepare` / `world_commit` /
//! `world_abort` and `stop` are the kit's.
//!
//! Why: Choreonoid shows a planning result in its graphics window; a headless
//! robot PC needs the same from a browser, a picture or a file, without
//! slowing the planners (it only listens).
//!
//! How: plan and motion results come from the host's publications
//! (`<ns>/planner/result/plan`, `<ns>/motion/result/plan`); nothing of the
//! viewer runs on a planner's call path.
//!
//! Config keys (beside the kit's `model_roots`, `limits`, `max_samples`):
//! `web` — the address to serve on (default `127.0.0.1:17448`; `"off"`: no
//! web view), `web_public` — allow a non-loopback `web` address (default
//! false), `web_fallback` — serve on a free port when `web`'s is taken
//! (default true; the log and `state` say where), `web_max_clients` —
//! connections at once (default 16).

use std::net::SocketAddr;
use std::sync::Arc;
use std::thread::JoinHandle;

use base64::Engine;
use nalgebra::Vector3;
use serde::Deserialize;
use serde_json::json;
use tsukami_msgs::error::parse_request;
use tsukami_msgs::keys::{world, ROLE_RESULT_VIEWER};
use tsukami_planner_kit::PlannerConfig;
use tsukami_plugin_api::{CallContext, CallError, Host, LogLevel, Plugin, PluginInfo};
use tsukami_render::grasp_view::DEFAULT_EYE;

use crate::latest::Board;
use crate::viewer::Viewer;
use crate::web::WebServer;
use crate::world::ViewerWorld;

/// The default address of the web view.
pub const DEFAULT_WEB: &str = "127.0.0.1:17448";
/// Largest picture edge (pixels).
pub const MAX_EDGE: u32 = 4096;

/// The web settings of the plugin config.
#[derive(Debug, Clone, PartialEq)]
pub struct WebConfig {
    /// Where to serve; `None`: no web view.
    pub addr: Option<SocketAddr>,
    /// Serve on a free port when `addr`'s is taken.
    pub fallback: bool,
    /// Connections at once.
    pub max_clients: usize,
}

/// The web settings from the plugin config's own keys; unknown keys are refused.
pub fn web_config(table: &toml::Table) -> Result<WebConfig, String> {
    let mut t = table.clone();
    let mut flag = |key: &str, default: bool| match t.remove(key) {
        None => Ok(default),
        Some(v) => v
            .as_bool()
            .ok_or_else(|| format!("plugin config: `{key}` must be true or false")),
    };
    let public = flag("web_public", false)?;
    let fallback = flag("web_fallback", true)?;
    let addr = match t.remove("web") {
        None => Some(DEFAULT_WEB.to_owned()),
        Some(toml::Value::String(s)) if s == "off" => None,
        Some(toml::Value::String(s)) => Some(s),
        Some(_) => return Err("plugin config: `web` must be an address or \"off\"".into()),
    };
    let addr = match addr {
        None => None,
        Some(s) => {
            let a: SocketAddr = s.parse().map_err(|_| {
                format!("plugin config: `web` = {s:?} is not an IP address and port")
            })?;
            if !a.ip().is_loopback() && !public {
                return Err(format!("plugin config: `web` = {s:?} is not loopback; set `web_public = true` to serve beyond this machine"));
            }
            Some(a)
        }
    };
    let max_clients = match t.remove("web_max_clients") {
        None => 16,
        Some(v) => v
            .as_integer()
            .filter(|n| (1..=256).contains(n))
            .ok_or("plugin config: `web_max_clients` must be an integer from 1 to 256")?
            as usize,
    };
    if let Some(k) = t.keys().next() {
        return Err(format!("plugin config: unknown key `{k}`"));
    }
    Ok(WebConfig {
        addr,
        fallback,
        max_clients,
    })
}

/// `render`'s request.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderRequest {
    #[serde(default = "default_width")]
    width: u32,
    #[serde(default = "default_height")]
    height: u32,
    /// Camera position relative to what it looks at (m, world frame).
    #[serde(default)]
    eye: Option<[f64; 3]>,
}

fn default_width() -> u32 {
    800
}

fn default_height() -> u32 {
    600
}

fn call_error(r: tsukami_msgs::ErrorReply) -> CallError {
    let mut e = CallError::new(r.error.code.as_str(), r.error.message);
    if let Some(d) = r.error.details {
        e.details_json = d.to_string();
    }
    e
}

fn parse<T: serde::de::DeserializeOwned>(payload: &[u8]) -> Result<T, CallError> {
    let payload: &[u8] = if payload.iter().all(u8::is_ascii_whitespace) {
        b"{}"
    } else {
        payload
    };
    parse_request(payload).map_err(call_error)
}

fn invalid(field: &str, message: &str) -> CallError {
    let mut e = CallError::new("invalid_value", format!("{field}: {message}"));
    e.details_json = json!({ "field": field }).to_string();
    e
}

/// A viewer error (`code: message`) as a call error.
fn viewer_error(message: String) -> CallError {
    match message.split_once(": ") {
        Some(("not_ready", m)) => CallError::new("not_ready", m),
        _ => CallError::new("internal", message),
    }
}

/// The plugin (see the module docs).
pub struct ViewerPlugin {
    viewer: Arc<Viewer>,
    web: Option<WebServer>,
    followers: Vec<JoinHandle<()>>,
}

impl ViewerPlugin {
    fn render(&self, payload: &[u8]) -> Result<Vec<u8>, CallError> {
        let req: RenderRequest = parse(payload)?;
        for (field, v) in [("width", req.width), ("height", req.height)] {
            if !(16..=MAX_EDGE).contains(&v) {
                return Err(invalid(field, &format!("must be 16 to {MAX_EDGE} pixels")));
            }
        }
        let eye = Vector3::from(req.eye.unwrap_or(DEFAULT_EYE));
        if !eye.iter().all(|c| c.is_finite()) || !(0.01..=100.0).contains(&eye.norm()) {
            return Err(invalid(
                "eye",
                "must be finite, 0.01 to 100 m from the target",
            ));
        }
        let picture = self
            .viewer
            .render(req.width, req.height, eye)
            .map_err(viewer_error)?;
        let reply = json!({
            "png_base64": base64::engine::general_purpose::STANDARD.encode(&picture.png),
            "width": req.width,
            "height": req.height,
            "posture": picture.posture,
            "triangles": picture.triangles,
            "world_version": picture.world_version,
        });
        Ok(reply.to_string().into_bytes())
    }

    fn glb(&self, payload: &[u8]) -> Result<Vec<u8>, CallError> {
        let _: serde_json::Map<String, serde_json::Value> = parse(payload)?;
        let (glb, version) = self.viewer.glb().map_err(viewer_error)?;
        let reply = json!({
            "glb_base64": base64::engine::general_purpose::STANDARD.encode(&glb),
            "bytes": glb.len(),
            "world_version": version,
        });
        Ok(reply.to_string().into_bytes())
    }

    fn state(&self, payload: &[u8]) -> Result<Vec<u8>, CallError> {
        let _: serde_json::Map<String, serde_json::Value> = parse(payload)?;
        let mut state: serde_json::Value =
            serde_json::from_slice(&self.viewer.state_json()).unwrap_or_default();
        if let Some(s) = state.as_object_mut() {
            // The page's postures: hundreds of numbers nobody reads in a reply.
            s.remove("posture");
            if let Some(c) = s.get_mut("controller").and_then(|c| c.as_object_mut()) {
                c.remove("links");
            }
            let ordering = std::sync::atomic::Ordering::Relaxed;
            s.insert(
                "web".into(),
                json!({
                    "url": self.web.as_ref().map(WebServer::url),
                    "event_clients": self.viewer.event_clients.load(ordering),
                    "events_sent": self.viewer.events_sent.load(ordering),
                }),
            );
        }
        Ok(state.to_string().into_bytes())
    }
}

impl Plugin for ViewerPlugin {
    fn info() -> PluginInfo {
        PluginInfo::new(
            "tsukami-result-viewer",
            env!("CARGO_PKG_VERSION"),
            &[ROLE_RESULT_VIEWER],
            "the planned grasp and motion: live in a browser (three.js), as a PNG picture, as a glTF .glb",
        )
        .with_capabilities(&[PluginInfo::WORLD, PluginInfo::CONCURRENT])
    }

    fn new(host: Host, config: &str) -> Result<Self, String> {
        let config = PlannerConfig::parse(config)?;
        let web = web_config(&config.planner)?;
        let board = Arc::new(Board::default());
        let viewer = Arc::new(Viewer::new(ViewerWorld::session(&config)?, board.clone()));
        let server = match web.addr {
            Some(addr) => {
                let server = WebServer::start(addr, web.fallback, web.max_clients, viewer.clone())
                    .map_err(|e| format!("result viewer: serving on {addr}: {e}"))?;
                host.log(
                    LogLevel::Info,
                    &format!("result viewer: open {} in a browser", server.url()),
                );
                Some(server)
            }
            None => None,
        };
        let followers = match crate::follow::follow(&host, &board) {
            Ok(f) => f,
            Err(e) => {
                board.close();
                return Err(format!("result viewer: {e}"));
            }
        };
        Ok(ViewerPlugin {
            viewer,
            web: server,
            followers,
        })
    }

    fn call(
        &self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        match command {
            "render" => self.render(payload),
            "glb" => self.glb(payload),
            "state" => self.state(payload),
            // The kit's session would answer a grasp plan; the viewer plans nothing.
            "plan" => Err(CallError::unknown_command(command)),
            _ => {
                let reply =
                    self.viewer
                        .session
                        .handle(command, payload, ctx.cancel_flag(), &mut |_| {})?;
                if command == world::COMMIT || world::CHANGES.contains(&command) {
                    // The page fetches the new bodies.
                    self.viewer.board.touch();
                }
                Ok(reply)
            }
        }
    }
}

impl Drop for ViewerPlugin {
    fn drop(&mut self) {
        self.viewer.board.close();
        self.web = None;
        for f in self.followers.drain(..) {
            let _ = f.join();
        }
    }
}

tsukami_plugin_api::export_plugin!(ViewerPlugin);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn web_config_defaults_to_loopback_and_refuses_the_rest() {
        let c = web_config(&toml::Table::new()).unwrap();
        assert_eq!(c.addr, Some(DEFAULT_WEB.parse().unwrap()));
        let t = |s: &str| web_config(&toml::from_str(s).unwrap());
        assert_eq!(t("web = \"off\"").unwrap().addr, None);
        let err = t("web = \"0.0.0.0:80\"").unwrap_err();
        assert!(err.contains("web_public"), "{err}");
        assert!(t("web = \"0.0.0.0:80\"\nweb_public = true").is_ok());
        assert!(t("web = \"nowhere\"").unwrap_err().contains("`web`"));
        assert!(t("web_max_clients = 0").is_err());
        assert!(t("colour = 1").unwrap_err().contains("`colour`"));
    }
}
