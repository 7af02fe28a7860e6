//! One world for every plugin: the robot, the object and the obstacles, set once
//! on the bus and seen by every world-aware plugin at the same version.
//!
//! What: [`WorldHub`] serves `<ns>/world/{set_robot,set_object,set_env,remove_env,get}`
//! (and takes the old `<ns>/planner/set_*` keys from the role callbacks). Each
//! change gets the next version and goes to every plugin that declares the
//! `world` capability, in two phases: `world_prepare` on all (each checks and
//! builds it beside its current world), then `world_commit` on all — or
//! `world_abort` on all if any refused, and the client gets that refusal. The
//! hub keeps the accepted requests, which `world/get` returns with the version.
//!
//! Why: the grasp planner, and later the trajectory planner and the viewer,
//! must plan on the same robot, object and obstacles (Choreonoid's BodyItems,
//! MoveIt's PlanningScene). Setting each plugin by its own commands lets them
//! drift apart.
//!
//! How: one thread applies changes in arrival order (the queue is bounded; a
//! full queue answers `busy`). It calls the plugins directly (their `call` is
//! `&self` and thread-safe), so a change does not wait behind a running plan,
//! and a running plan keeps the world snapshot it started with.

use std::sync::atomic::AtomicBool;
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use tsukami_msgs::host::{WorldChange, WorldPrepare, WorldState, WorldVersion};
use tsukami_msgs::keys::{planner as cmd, world, KeySpace};
use tsukami_msgs::{ErrorCode, ErrorReply};
use tsukami_plugin_api::loader::PluginInstance;
use tsukami_plugin_api::CallError;
use zenoh::query::{Query, Queryable};
use zenoh::Wait;

use crate::reply::{check_payload, reply_error, reply_json, ResultOut};

/// A plugin that shares the world.
pub struct Member {
    /// Its role.
    pub role: String,
    /// The plugin.
    pub plugin: Arc<PluginInstance>,
}

/// A world change waiting for the hub's thread.
struct Change {
    command: String,
    query: Query,
}

/// The host's world: its members, its state and the thread applying changes.
pub struct WorldHub {
    queue: mpsc::SyncSender<Change>,
    state: Arc<Mutex<WorldState>>,
    thread: Option<JoinHandle<()>>,
}

fn call(member: &Member, command: &str, payload: &[u8]) -> Result<Vec<u8>, CallError> {
    member
        .plugin
        .call(command, payload, &AtomicBool::new(false))
}

fn to_reply(role: &str, e: CallError) -> ErrorReply {
    let mut reply = ErrorReply::new(ErrorCode::from_wire(&e.code), e.message);
    let mut details: serde_json::Value =
        serde_json::from_str(&e.details_json).unwrap_or_else(|_| serde_json::json!({}));
    if details.is_object() {
        details["role"] = role.into();
    }
    reply = reply.with_details(details);
    reply
}

/// Applies `change` as `version` on every member: prepare all, then commit all,
/// or abort all. The first member's reply, or the first refusal.
fn apply(members: &[Member], change: WorldChange, version: u64) -> Result<Vec<u8>, ErrorReply> {
    let prepare = serde_json::to_vec(&WorldPrepare { version, change })
        .map_err(|e| ErrorReply::new(ErrorCode::Internal, e.to_string()))?;
    let v = serde_json::to_vec(&WorldVersion { version }).unwrap_or_default();
    let mut first = None;
    for (i, m) in members.iter().enumerate() {
        match call(m, world::PREPARE, &prepare) {
            Ok(reply) => {
                first.get_or_insert(reply);
            }
            Err(e) => {
                for prepared in &members[..i] {
                    let _ = call(prepared, world::ABORT, &v);
                }
                return Err(to_reply(&m.role, e));
            }
        }
    }
    for m in members {
        if let Err(e) = call(m, world::COMMIT, &v) {
            // A commit only swaps a prepared snapshot in; failing means the
            // plugin lost it, which the log must show.
            tracing::error!(role = m.role.as_str(), "world commit {version} failed: {e}");
        }
    }
    first.ok_or_else(|| ErrorReply::new(ErrorCode::NoPlugin, "no plugin shares the world"))
}

/// Records an accepted change in the host's copy of the world.
fn record(state: &mut WorldState, change: WorldChange, version: u64) {
    state.version = version;
    match change {
        WorldChange::SetRobot(r) => state.robot = Some(r),
        WorldChange::SetObject(o) => state.object = Some(o),
        WorldChange::SetEnv(env) => {
            if env.replace {
                state.obstacles.clear();
            }
            for o in env.obstacles {
                state.obstacles.retain(|x| x.name != o.name);
                state.obstacles.push(o);
            }
            state.obstacles.sort_by(|a, b| a.name.cmp(&b.name));
        }
        WorldChange::RemoveEnv(r) if r.all => state.obstacles.clear(),
        WorldChange::RemoveEnv(r) => state.obstacles.retain(|x| !r.names.contains(&x.name)),
    }
}

fn serve(
    members: Vec<Member>,
    state: Arc<Mutex<WorldState>>,
    changes: mpsc::Receiver<Change>,
    results: ResultOut,
) {
    while let Ok(Change { command, query }) = changes.recv() {
        let bytes = query
            .payload()
            .map(|p| p.to_bytes().into_owned())
            .unwrap_or_default();
        let change = match WorldChange::parse(&command, &bytes) {
            Some(Ok(change)) => change,
            Some(Err(e)) => {
                reply_error(&query, e);
                continue;
            }
            None => continue,
        };
        let version = state.lock().unwrap_or_else(|p| p.into_inner()).version + 1;
        match apply(&members, change.clone(), version) {
            Ok(reply) => {
                record(
                    &mut state.lock().unwrap_or_else(|p| p.into_inner()),
                    change,
                    version,
                );
                reply_json(&query, reply.clone());
                // `<ns>/world/result/<command>`: what the viewer draws OCP boxes from.
                results.publish(&command, reply);
            }
            Err(e) => reply_error(&query, e),
        }
    }
}

impl WorldHub {
    /// Starts the hub for `members` (the plugins declaring `world`); `max_queue`
    /// changes may wait, more are answered `busy`.
    /// Accepted changes' replies are published through `results`.
    pub(crate) fn start(
        members: Vec<Member>,
        max_queue: usize,
        results: ResultOut,
    ) -> Result<WorldHub> {
        let roles = members.iter().map(|m| m.role.clone()).collect();
        let state = Arc::new(Mutex::new(WorldState {
            plugins: roles,
            ..WorldState::default()
        }));
        let (queue, changes) = mpsc::sync_channel(max_queue.max(1));
        let shared = state.clone();
        let thread = std::thread::Builder::new()
            .name("world".into())
            .spawn(move || serve(members, shared, changes, results))
            .context("spawning the world thread")?;
        Ok(WorldHub {
            queue,
            state,
            thread: Some(thread),
        })
    }

    /// Queues a world change (`command` is one of `keys::world::CHANGES`).
    pub fn submit(&self, command: &str, query: Query) {
        let change = Change {
            command: command.to_owned(),
            query,
        };
        if let Err(mpsc::TrySendError::Full(c) | mpsc::TrySendError::Disconnected(c)) =
            self.queue.try_send(change)
        {
            reply_error(
                &c.query,
                ErrorReply::new(ErrorCode::Busy, "too many world changes are waiting; retry"),
            );
        }
    }

    /// Declares `<ns>/world/**`.
    pub fn serve_keys(
        self: &Arc<Self>,
        session: &zenoh::Session,
        keys: &KeySpace,
        max_bytes: usize,
    ) -> Result<Queryable<()>> {
        let wildcard = keys.world("**");
        let prefix = keys.world("");
        let hub = self.clone();
        session
            .declare_queryable(&wildcard)
            .callback(move |query| {
                let command = query
                    .key_expr()
                    .as_str()
                    .strip_prefix(prefix.as_str())
                    .unwrap_or("")
                    .to_owned();
                if command == world::GET {
                    let state = hub.state.lock().unwrap_or_else(|p| p.into_inner()).clone();
                    return reply_json(&query, serde_json::to_vec(&state).unwrap_or_default());
                }
                if !world::CHANGES.contains(&command.as_str()) {
                    let known = [
                        world::GET,
                        cmd::SET_ROBOT,
                        cmd::SET_OBJECT,
                        cmd::SET_ENV,
                        cmd::REMOVE_ENV,
                    ];
                    return reply_error(
                        &query,
                        ErrorReply::new(
                            ErrorCode::UnknownCommand,
                            format!(
                                "unknown world command `{command}`; the world answers {known:?}"
                            ),
                        ),
                    );
                }
                match check_payload(&query, max_bytes) {
                    Ok(()) => hub.submit(&command, query),
                    Err(e) => reply_error(&query, e),
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("declaring {wildcard}: {e}"))
    }

    /// The world as the host holds it.
    pub fn state(&self) -> WorldState {
        self.state.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }
}

impl Drop for WorldHub {
    fn drop(&mut self) {
        // The queue's sender is ours; replacing it ends the thread's `recv`
        // once the queryables holding clones of the hub are gone.
        if let Some(t) = self.thread.take() {
            drop(std::mem::replace(&mut self.queue, mpsc::sync_channel(1).0));
            let _ = t.join();
        }
    }
}

/// The worker count of a plugin: if it declares `concurrent`, its config's
/// `workers` or else [`default_workers`] (at most 64); otherwise 1.
pub fn workers_for(
    entry: &crate::config::PluginEntryConfig,
    info: &tsukami_plugin_api::PluginInfo,
) -> usize {
    if info.has(tsukami_plugin_api::PluginInfo::CONCURRENT) {
        entry.workers.unwrap_or_else(default_workers).clamp(1, 64)
    } else {
        1
    }
}

/// A concurrent plugin's pool when its config names none: one worker per core
/// the process may use (1 when that cannot be told).
pub fn default_workers() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}

/// A plugin as the server created it.
pub type Created<'c> = (
    &'c crate::config::PluginEntryConfig,
    tsukami_plugin_api::loader::LoadedLibrary,
    tsukami_plugin_api::PluginInfo,
    Arc<PluginInstance>,
);

/// Starts the hub for the created plugins that declare `world` and declares
/// `<ns>/world/**`; `None` (and no keys) when no plugin shares the world.
pub fn start(
    session: &zenoh::Session,
    keys: &KeySpace,
    config: &crate::config::HostConfig,
    created: &[Created<'_>],
    queryables: &mut Vec<Queryable<()>>,
) -> Result<Option<Arc<WorldHub>>> {
    let members: Vec<Member> = created
        .iter()
        .filter(|(_, _, info, _)| info.has(tsukami_plugin_api::PluginInfo::WORLD))
        .map(|(entry, _, _, plugin)| Member {
            role: entry.role.clone(),
            plugin: plugin.clone(),
        })
        .collect();
    if members.is_empty() {
        return Ok(None);
    }
    let results = ResultOut {
        session: session.clone(),
        keys: keys.clone(),
        role: world::PREFIX.to_owned(),
    };
    let hub = Arc::new(WorldHub::start(members, config.limits.max_queue, results)?);
    queryables.push(hub.serve_keys(session, keys, config.limits.max_payload_bytes)?);
    Ok(Some(hub))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tsukami_plugin_api::PluginInfo;

    #[test]
    fn concurrent_plugins_get_the_cores_unless_configured() {
        let mut entry: crate::config::PluginEntryConfig =
            toml::from_str(r#"role = "grasp-planner""#).unwrap();
        let plain = PluginInfo::new("p", "0", &["grasp-planner"], "");
        let concurrent = plain.clone().with_capabilities(&[PluginInfo::CONCURRENT]);
        assert!(default_workers() >= 1);
        assert_eq!(workers_for(&entry, &concurrent), default_workers().min(64));
        assert_eq!(workers_for(&entry, &plain), 1);
        entry.workers = Some(3);
        assert_eq!(workers_for(&entry, &concurrent), 3);
        assert_eq!(workers_for(&entry, &plain), 1);
        entry.workers = Some(0);
        assert_eq!(workers_for(&entry, &concurrent), 1);
    }
}
