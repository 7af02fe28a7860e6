//! The running host: plugins loaded, one zenoh session, each role's queries routed
//! to its plugin.
//!
//! Each plugin instance lives on its own worker thread and is called one command at
//! a time with `&mut self` — no locks inside plugins. zenoh's query callback only
//! checks the request (size, JSON syntax) and queues it for the worker, so the
//! callback never blocks. Two things are answered by the host itself, in the
//! callback, so they work while a plugin is busy: `<ns>/<role>/stop` (sets the
//! running call's cancel flag; the plugin sees it at its next poll) and
//! `<ns>/host/plugins`. The host's own commands to its plugins
//! (`world_prepare`, `world_commit`, `world_abort`) are refused on every
//! role's keys: only the world hub calls them.
//!
//! Work is bounded: each plugin's queue holds at most `limits.max_queue` requests
//! (more get `busy`), a queued request keeps only zenoh's own copy of its payload,
//! and a watchdog raises a call's cancel flag once it has run `limits.max_call_ms`.

use crate::config::HostConfig;
use crate::host_handle::BusHost;
use crate::reply::{check_payload, reply_error, reply_json, ResultOut};
use crate::world::WorldHub;
use anyhow::{bail, Context, Result};
use std::borrow::Cow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tsukami_msgs::host::{PluginEntry, PluginsReply, StopReply};
use tsukami_msgs::keys::{self, KeySpace};
use tsukami_msgs::{ErrorCode, ErrorReply};
use tsukami_plugin_api::loader::{LoadedLibrary, PluginInstance};
use tsukami_plugin_api::INTERFACE_VERSION;
use zenoh::query::{Query, Queryable};
use zenoh::Wait;

/// A request queued for a plugin's worker. The payload stays inside the query
/// (zenoh's buffer): it is held once, and read only when the call starts.
struct Job {
    command: String,
    query: Query,
}

/// What the worker is running now, so `stop` and the watchdog can cancel it.
#[derive(Default)]
struct CurrentCall {
    command: Option<String>,
    cancel: Arc<AtomicBool>,
    /// When the running call started.
    started: Option<Instant>,
    /// The watchdog raised the cancel flag (the call hit `limits.max_call_ms`).
    timed_out: bool,
}

/// The shared side of one plugin's workers: its queue, its current calls and,
/// for a world-aware plugin, the world hub its `set_*` commands go to.
struct Worker {
    queue: mpsc::SyncSender<Job>,
    current: Arc<Mutex<CurrentCall>>,
    /// The other workers' calls (a `concurrent` plugin with several workers).
    more: Vec<Arc<Mutex<CurrentCall>>>,
    world: Option<Arc<WorldHub>>,
}

/// How often the watchdog looks at the running call.
const WATCHDOG_TICK: Duration = Duration::from_millis(10);

/// The per-worker limits the host enforces itself.
#[derive(Debug, Clone, Copy)]
struct WorkLimits {
    max_payload_bytes: usize,
    max_queue: usize,
    max_call: Duration,
}

impl Worker {
    /// Sets the running call's cancel flag; answers what was running.
    fn stop(&self) -> StopReply {
        let mut stopped = None;
        for other in &self.more {
            let slot = lock(other);
            if let Some(command) = &slot.command {
                slot.cancel.store(true, Ordering::Relaxed);
                stopped.get_or_insert(command.clone());
            }
        }
        let current = lock(&self.current);
        if current.command.is_none() && stopped.is_some() {
            return StopReply {
                stopped: true,
                command: stopped,
            };
        }
        match &current.command {
            Some(command) => {
                current.cancel.store(true, Ordering::Relaxed);
                StopReply {
                    stopped: true,
                    command: Some(command.clone()),
                }
            }
            None => StopReply {
                stopped: false,
                command: None,
            },
        }
    }
}

/// A host serving its plugins on the bus until dropped or shut down.
pub struct RunningHost {
    session: zenoh::Session,
    keys: KeySpace,
    plugins: PluginsReply,
    queryables: Vec<Queryable<()>>,
    workers: Vec<JoinHandle<()>>,
}

/// The payload a plugin gets: the query's bytes (borrowed when zenoh holds them
/// in one piece), or `{}` when blank.
fn call_payload(query: &Query) -> Cow<'_, [u8]> {
    match query.payload().map(|p| p.to_bytes()) {
        Some(bytes) if !bytes.iter().all(u8::is_ascii_whitespace) => bytes,
        _ => Cow::Borrowed(b"{}"),
    }
}

/// The refusal of a host-to-plugin command sent on the bus (`unknown_command`,
/// naming the command and the role): only the host's world hub calls them.
/// `error` marked `details.fallback: true`: the host's answer for a prefix it
/// does not serve, which a caller sets aside when the prefix's own component
/// answers too (`tsukami_bus::client::query`).
fn as_fallback(mut error: ErrorReply) -> ErrorReply {
    let details = error
        .error
        .details
        .get_or_insert_with(|| serde_json::json!({}));
    if let Some(map) = details.as_object_mut() {
        map.insert("fallback".into(), true.into());
    }
    error
}

fn host_only(role: &str, command: &str) -> ErrorReply {
    ErrorReply::new(
        ErrorCode::UnknownCommand,
        format!(
            "`{command}` is the host's own command to its plugins, not a bus command of role {role}; \
             change the world with <ns>/world/set_robot, set_object, set_env or remove_env"
        ),
    )
    .with_details(serde_json::json!({ "role": role, "command": command }))
}

fn lock(current: &Mutex<CurrentCall>) -> std::sync::MutexGuard<'_, CurrentCall> {
    current.lock().unwrap_or_else(|p| p.into_inner())
}

fn worker_loop(
    plugin: Arc<PluginInstance>,
    name: String,
    jobs: Arc<Mutex<mpsc::Receiver<Job>>>,
    current: Arc<Mutex<CurrentCall>>,
    max_call: Duration,
    results: Option<Arc<ResultOut>>,
) {
    // Workers of one plugin share its queue; each takes the next job.
    let next = || jobs.lock().unwrap_or_else(|p| p.into_inner()).recv();
    while let Ok(job) = next() {
        let cancel = Arc::new(AtomicBool::new(false));
        {
            let mut slot = lock(&current);
            slot.command = Some(job.command.clone());
            slot.cancel = cancel.clone();
            slot.started = Some(Instant::now());
            slot.timed_out = false;
        }
        let result = plugin.call(&job.command, &call_payload(&job.query), &cancel);
        let timed_out = {
            let mut slot = lock(&current);
            slot.command = None;
            slot.started = None;
            slot.timed_out
        };
        let publish = |bytes: Vec<u8>| {
            if let Some(out) = &results {
                out.publish(&job.command, bytes);
            }
        };
        match result {
            Ok(bytes) => {
                reply_json(&job.query, bytes.clone());
                publish(bytes);
            }
            Err(err) => {
                if err.code == tsukami_plugin_api::CallError::PANICKED {
                    tracing::error!(plugin = name.as_str(), "{}", err.message);
                }
                let code = ErrorCode::from_wire(&err.code);
                let mut reply = if timed_out && code == ErrorCode::Cancelled {
                    ErrorReply::new(
                        code,
                        format!(
                            "the call ran for the host's limit of limits.max_call_ms = {} ms and was cancelled: {}",
                            max_call.as_millis(),
                            err.message
                        ),
                    )
                } else {
                    ErrorReply::new(code, err.message)
                };
                if let Ok(details) = serde_json::from_str(&err.details_json) {
                    reply = reply.with_details(details);
                } else if timed_out && code == ErrorCode::Cancelled {
                    reply = reply.with_details(serde_json::json!({
                        "limit": "max_call_ms",
                        "max_call_ms": max_call.as_millis() as u64,
                    }));
                }
                let bytes = reply.to_json_bytes();
                reply_error(&job.query, reply);
                publish(bytes);
            }
        }
    }
}

/// Raises the running call's cancel flag once it has run `max_call`; ends when
/// the worker and its queryable are gone.
fn watchdog(current: Weak<Mutex<CurrentCall>>, max_call: Duration) {
    loop {
        std::thread::sleep(WATCHDOG_TICK);
        let Some(current) = current.upgrade() else {
            return;
        };
        let mut slot = lock(&current);
        let overdue = slot.started.is_some_and(|t| t.elapsed() >= max_call);
        if overdue && !slot.timed_out {
            slot.cancel.store(true, Ordering::Relaxed);
            slot.timed_out = true;
        }
    }
}

/// Opens the host's session. With the built-in bus config, zenoh's reassembly
/// buffer is capped at twice `limits.max_payload_bytes` plus 1 MiB
/// ([`tsukami_bus::reassembly_cap`], zenoh's default is 1 GiB), so an oversized
/// request cannot grow the host before it is refused; a user's zenoh config sets
/// its own (`transport/link/rx/max_message_size`).
fn open_session(config: &HostConfig) -> Result<zenoh::Session> {
    config.bus.open_bounded(config.limits.max_payload_bytes)
}

/// The key prefixes this host answers itself: its plugins' roles, and `world`
/// when it holds a world. `stop` on any other prefix is answered `no_plugin`.
fn served_prefixes(config: &HostConfig, world: bool) -> Vec<String> {
    let roles = config.plugins.iter().map(|p| keys::role_prefix(&p.role));
    let world = world.then_some(keys::world::PREFIX);
    roles.chain(world).map(str::to_owned).collect()
}

/// A plugin's file as `host/plugins` lists it: the file name only, never the
/// absolute folder.
fn listed_path(path: &std::path::Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

impl RunningHost {
    /// Loads every plugin of `config`, opens the bus and starts serving.
    ///
    /// Fails — loading nothing — if any plugin file is missing, incompatible, does not
    /// provide its configured role, or fails to start.
    pub fn start(config: &HostConfig) -> Result<RunningHost> {
        let keys = KeySpace::new(&config.namespace);
        let mut libraries = Vec::new();
        for entry in &config.plugins {
            let file = config.plugin_file(entry)?;
            let library = LoadedLibrary::load(&file)?;
            if !library.info().roles.iter().any(|r| r == &entry.role) {
                bail!(
                    "plugin `{}` ({}) does not provide role `{}`; it provides {:?}",
                    library.info().name,
                    file.display(),
                    entry.role,
                    library.info().roles
                );
            }
            if libraries.iter().any(
                |(e, _): &(&crate::config::PluginEntryConfig, LoadedLibrary)| e.role == entry.role,
            ) {
                bail!("two plugins are configured for role `{}`", entry.role);
            }
            libraries.push((entry, library));
        }

        let session = open_session(config)?;
        let mut host = RunningHost {
            session: session.clone(),
            keys: keys.clone(),
            plugins: PluginsReply {
                interface_version: INTERFACE_VERSION.to_owned(),
                namespace: config.namespace.clone(),
                plugins: vec![],
            },
            queryables: vec![],
            workers: vec![],
        };

        let mut created = Vec::new();
        for (entry, library) in libraries {
            let info = library.info().clone();
            let progress_key = keys.progress(&entry.role);
            let bus_host = BusHost::new(
                session.clone(),
                keys.clone(),
                progress_key,
                info.name.clone(),
            );
            let plugin_config = config.plugin_config_text(entry);
            let instance = Arc::new(library.create(bus_host.into_ffi(), &plugin_config)?);
            created.push((entry, library, info, instance));
        }
        let world = crate::world::start(&session, &keys, config, &created, &mut host.queryables)?;
        for (entry, library, info, instance) in created {
            let limits = WorkLimits {
                max_payload_bytes: config.limits.max_payload_bytes,
                max_queue: config.limits.max_queue.max(1),
                max_call: Duration::from_millis(config.limits.max_call_ms),
            };
            let (queue, jobs) = mpsc::sync_channel(limits.max_queue);
            let jobs = Arc::new(Mutex::new(jobs));
            let n_workers = crate::world::workers_for(entry, &info);
            // The viewer's own replies (pictures) are not results to follow.
            let results = (entry.role != keys::ROLE_RESULT_VIEWER).then(|| {
                Arc::new(ResultOut {
                    session: session.clone(),
                    keys: keys.clone(),
                    role: entry.role.clone(),
                })
            });
            let mut slots = Vec::new();
            for k in 0..n_workers {
                let current = Arc::new(Mutex::new(CurrentCall::default()));
                slots.push(current.clone());
                let (name, jobs, plugin) = (info.name.clone(), jobs.clone(), instance.clone());
                let results = results.clone();
                let watched = Arc::downgrade(&current);
                std::thread::Builder::new()
                    .name(format!("watchdog-{}-{k}", entry.role))
                    .spawn(move || watchdog(watched, limits.max_call))
                    .context("spawning a plugin watchdog thread")?;
                host.workers.push(
                    std::thread::Builder::new()
                        .name(format!("plugin-{}-{k}", entry.role))
                        .spawn(move || {
                            worker_loop(plugin, name, jobs, current, limits.max_call, results)
                        })
                        .context("spawning a plugin worker thread")?,
                );
            }
            let worker = Worker {
                queue,
                current: slots.remove(0),
                more: slots,
                world: world
                    .as_ref()
                    .filter(|_| info.has(tsukami_plugin_api::PluginInfo::WORLD))
                    .cloned(),
            };
            host.queryables.push(Self::serve_role(
                &session,
                &keys,
                &entry.role,
                worker,
                limits,
            )?);
            tracing::info!(
                plugin = info.name.as_str(),
                version = info.version.as_str(),
                role = entry.role.as_str(),
                "plugin loaded from {}",
                library.path().display()
            );
            host.plugins.plugins.push(PluginEntry {
                name: info.name,
                version: info.version,
                roles: vec![entry.role.clone()],
                description: info.description,
                path: listed_path(library.path()),
                capabilities: info.capabilities.clone(),
                workers: n_workers,
            });
        }

        let served = served_prefixes(config, world.is_some());
        host.queryables
            .push(Self::answer_stop_without_plugin(&session, &keys, served)?);
        let listing = serde_json::to_vec(&host.plugins)?;
        let plugins_queryable = session
            .declare_queryable(keys.host_plugins())
            .callback(move |query| reply_json(&query, listing.clone()))
            .wait()
            .map_err(|e| anyhow::anyhow!("declaring {}: {e}", keys.host_plugins()))?;
        host.queryables.push(plugins_queryable);
        Ok(host)
    }

    fn serve_role(
        session: &zenoh::Session,
        keys: &KeySpace,
        role: &str,
        worker: Worker,
        limits: WorkLimits,
    ) -> Result<Queryable<()>> {
        let wildcard = keys.role_wildcard(role);
        let role_keys = keys.clone();
        let role_name = role.to_owned();
        session
            .declare_queryable(&wildcard)
            .callback(move |query| {
                let Some(command) = role_keys
                    .command_of(&role_name, query.key_expr().as_str())
                    .map(str::to_owned)
                else {
                    return reply_error(
                        &query,
                        ErrorReply::new(
                            ErrorCode::UnknownCommand,
                            format!("no command in key {}", query.key_expr()),
                        ),
                    );
                };
                if let Err(error) = check_payload(&query, limits.max_payload_bytes) {
                    return reply_error(&query, error);
                }
                if keys::world::HOST_ONLY.contains(&command.as_str()) {
                    return reply_error(&query, host_only(&role_name, &command));
                }
                if command == keys::STOP {
                    let reply = worker.stop();
                    return reply_json(&query, serde_json::to_vec(&reply).unwrap_or_default());
                }
                // `<ns>/planner/set_*` of a world-aware plugin: the shared world.
                if let Some(world) = &worker.world {
                    if keys::world::CHANGES.contains(&command.as_str()) {
                        return world.submit(&command, query);
                    }
                }
                match worker.queue.try_send(Job { command, query }) {
                    Ok(()) => {}
                    Err(mpsc::TrySendError::Full(job)) => reply_error(
                        &job.query,
                        ErrorReply::new(
                            ErrorCode::Busy,
                            format!(
                                "role {role_name} is busy: {} requests are queued, the host's limits.max_queue; retry later",
                                limits.max_queue
                            ),
                        ),
                    ),
                    Err(mpsc::TrySendError::Disconnected(job)) => {
                        tracing::error!("worker of role {role_name} has stopped");
                        reply_error(
                            &job.query,
                            ErrorReply::new(
                                ErrorCode::Internal,
                                format!("the worker of role {role_name} has stopped"),
                            ),
                        );
                    }
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("declaring {wildcard}: {e}"))
    }

    /// `<ns>/*/stop` for every prefix not in `served` — a built-in role no plugin
    /// fills, an unknown role, an absent component: answered with `no_plugin`
    /// naming the role (`details.role`); a garbage payload still gets
    /// `malformed_json` / `invalid_request`. A served prefix is left to its own
    /// queryable. Declared not complete. Every answer is marked
    /// `details.fallback: true`: where a component serves its own `<prefix>/stop`,
    /// Tsukami's callers (target `All`) get both answers and keep the component's
    /// (`tsukami_bus::client::query`), also for a payload the host would refuse.
    fn answer_stop_without_plugin(
        session: &zenoh::Session,
        keys: &KeySpace,
        served: Vec<String>,
    ) -> Result<Queryable<()>> {
        let key = keys.key(&format!("*/{}", keys::STOP));
        let prefix = keys.key("");
        session
            .declare_queryable(&key)
            .complete(false)
            .callback(move |query| {
                let key = query.key_expr().as_str();
                let role = key
                    .strip_prefix(prefix.as_str())
                    .and_then(|k| k.strip_suffix(&format!("/{}", keys::STOP)))
                    .unwrap_or(key)
                    .to_owned();
                if served.contains(&role) {
                    return; // the role's own queryable answers
                }
                let error = check_payload(&query, 1 << 20).err().unwrap_or_else(|| {
                    ErrorReply::new(
                        ErrorCode::NoPlugin,
                        format!("no plugin fills role `{role}` in this host; nothing to stop"),
                    )
                    .with_details(serde_json::json!({ "role": role }))
                });
                reply_error(&query, as_fallback(error));
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("declaring {key}: {e}"))
    }

    /// What `<ns>/host/plugins` answers.
    pub fn plugins(&self) -> &PluginsReply {
        &self.plugins
    }

    /// The key space it serves.
    pub fn keys(&self) -> &KeySpace {
        &self.keys
    }

    /// Stops serving: undeclares the queryables, lets the workers finish their
    /// queues, closes the session.
    pub fn shutdown(mut self) {
        self.stop_serving();
    }

    fn stop_serving(&mut self) {
        for queryable in self.queryables.drain(..) {
            let _ = queryable.undeclare().wait();
        }
        // The queues' senders lived in the queryable callbacks, now dropped: each
        // worker's `recv` ends once its queue is drained.
        for worker in self.workers.drain(..) {
            let _ = worker.join();
        }
        let _ = self.session.close().wait();
    }
}

impl Drop for RunningHost {
    fn drop(&mut self) {
        self.stop_serving();
    }
}
