//! The running host: plugins loaded, one zenoh session, each role's queries routed
//! to its plugin.
//!
//! Each plugin instance lives on its own worker thread and is called one command at
//! a time with `&mut self` — no locks inside plugins. zenoh's query callback only
//! checks the request (size, JSON syntax) and queues it for the worker, so the
//! callback never blocks. Two things are answered by the host itself, in the
//! callback, so they work while a plugin is busy: `<ns>/<role>/stop` (sets the
//! running call's cancel flag; the plugin sees it at its next poll) and
//! `<ns>/host/plugins`.

use crate::config::HostConfig;
use crate::host_handle::BusHost;
use anyhow::{bail, Context, Result};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use tsukami_msgs::host::{PluginEntry, PluginsReply, StopReply};
use tsukami_msgs::keys::{self, KeySpace};
use tsukami_msgs::{ErrorCode, ErrorReply};
use tsukami_plugin_api::loader::{LoadedLibrary, PluginInstance};
use tsukami_plugin_api::INTERFACE_VERSION;
use zenoh::bytes::Encoding;
use zenoh::query::{Query, Queryable};
use zenoh::Wait;

/// A request queued for a plugin's worker.
struct Job {
    command: String,
    payload: Vec<u8>,
    query: Query,
}

/// What the worker is running now, so `stop` can cancel it.
#[derive(Default)]
struct CurrentCall {
    command: Option<String>,
    cancel: Arc<AtomicBool>,
}

/// The shared side of one plugin's worker: its queue and its current call.
struct Worker {
    queue: mpsc::Sender<Job>,
    current: Arc<Mutex<CurrentCall>>,
}

impl Worker {
    /// Sets the running call's cancel flag; answers what was running.
    fn stop(&self) -> StopReply {
        let current = self.current.lock().unwrap_or_else(|p| p.into_inner());
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

fn reply_json(query: &Query, payload: Vec<u8>) {
    if let Err(e) = query
        .reply(query.key_expr().clone(), payload)
        .encoding(Encoding::APPLICATION_JSON)
        .wait()
    {
        tracing::warn!("reply on {} failed: {e}", query.key_expr());
    }
}

fn reply_error(query: &Query, error: ErrorReply) {
    tracing::debug!("error reply on {}: {error}", query.key_expr());
    if let Err(e) = query
        .reply_err(error.to_json_bytes())
        .encoding(Encoding::APPLICATION_JSON)
        .wait()
    {
        tracing::warn!("error reply on {} failed: {e}", query.key_expr());
    }
}

/// Checks a request before it reaches a plugin: size and JSON syntax. An empty
/// payload stands for `{}`.
fn checked_payload(query: &Query, max_bytes: usize) -> Result<Vec<u8>, ErrorReply> {
    let bytes = query
        .payload()
        .map(|p| p.to_bytes().into_owned())
        .unwrap_or_default();
    if bytes.len() > max_bytes {
        return Err(ErrorReply::new(
            ErrorCode::PayloadTooLarge,
            format!(
                "payload is {} bytes; this host accepts at most {max_bytes}",
                bytes.len()
            ),
        ));
    }
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Ok(b"{}".to_vec());
    }
    serde_json::from_slice::<serde::de::IgnoredAny>(&bytes).map_err(|e| {
        ErrorReply::new(
            ErrorCode::MalformedJson,
            format!("payload is not valid JSON: {e}"),
        )
    })?;
    Ok(bytes)
}

fn worker_loop(
    mut plugin: PluginInstance,
    name: String,
    jobs: mpsc::Receiver<Job>,
    current: Arc<Mutex<CurrentCall>>,
) {
    while let Ok(job) = jobs.recv() {
        let cancel = Arc::new(AtomicBool::new(false));
        {
            let mut slot = current.lock().unwrap_or_else(|p| p.into_inner());
            slot.command = Some(job.command.clone());
            slot.cancel = cancel.clone();
        }
        let result = plugin.call(&job.command, &job.payload, &cancel);
        current.lock().unwrap_or_else(|p| p.into_inner()).command = None;
        match result {
            Ok(bytes) => reply_json(&job.query, bytes),
            Err(err) => {
                if err.code == tsukami_plugin_api::CallError::PANICKED {
                    tracing::error!(plugin = name.as_str(), "{}", err.message);
                }
                let mut reply = ErrorReply::new(ErrorCode::from_wire(&err.code), err.message);
                if let Ok(details) = serde_json::from_str(&err.details_json) {
                    reply = reply.with_details(details);
                }
                reply_error(&job.query, reply);
            }
        }
    }
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

        let session = config.bus.open()?;
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

        for (entry, library) in libraries {
            let info = library.info().clone();
            let progress_key = keys.progress(&entry.role);
            let bus_host = BusHost::new(
                session.clone(),
                keys.clone(),
                progress_key,
                info.name.clone(),
            );
            let plugin_config = entry
                .config
                .as_ref()
                .map(|t| t.to_string())
                .unwrap_or_default();
            let instance = library.create(bus_host.into_ffi(), &plugin_config)?;
            let (queue, jobs) = mpsc::channel();
            let current = Arc::new(Mutex::new(CurrentCall::default()));
            let worker = Worker {
                queue,
                current: current.clone(),
            };
            let name = info.name.clone();
            host.workers.push(
                std::thread::Builder::new()
                    .name(format!("plugin-{}", entry.role))
                    .spawn(move || worker_loop(instance, name, jobs, current))
                    .context("spawning a plugin worker thread")?,
            );
            host.queryables.push(Self::serve_role(
                &session,
                &keys,
                &entry.role,
                worker,
                config.limits.max_payload_bytes,
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
                path: library.path().display().to_string(),
            });
        }

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
        max_bytes: usize,
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
                if command == keys::STOP {
                    let reply = worker.stop();
                    return reply_json(&query, serde_json::to_vec(&reply).unwrap_or_default());
                }
                match checked_payload(&query, max_bytes) {
                    Ok(payload) => {
                        if worker
                            .queue
                            .send(Job {
                                command,
                                payload,
                                query,
                            })
                            .is_err()
                        {
                            tracing::error!("worker of role {role_name} has stopped");
                        }
                    }
                    Err(error) => reply_error(&query, error),
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("declaring {wildcard}: {e}"))
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
