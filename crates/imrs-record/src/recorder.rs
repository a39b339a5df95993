//! The recorder: the cell's and the simulation's event streams, and the scene, into one MCAP
//! file, streamed as they come. The simulation is any [`World`]: the recorder draws what the
//! world gives it and knows no world's layout.

use std::collections::HashMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use foxglove::messages::{FrameTransforms, Log, SceneUpdate};
use foxglove::{Channel, Context, McapWriter, McapWriterHandle, RawChannel, Schema};
use imrs_core::Cell;
use imrs_scene::{Scene, World};
use serde_json::Value;

use crate::error::RecordError;
use crate::messages::{Route, SIM_SCHEMA, cell_log, cell_message, sim_log, sim_message};
use crate::scene::{self, Moved, Parts};
use crate::time::nanos;

/// Writes a cell's run into one MCAP file that Foxglove opens with no configuration.
///
/// | channel | schema | what |
/// |---|---|---|
/// | `/ports/PORT` | `imrs.PortEvent` (JSON) | each send, receive, query, response and failure on the port |
/// | `/modules/MODULE` | `imrs.ModuleEvent` (JSON) | sections entered and left, tasks, exceptions, steps, alarms |
/// | `/log` | `foxglove.Log` | exceptions, timeouts, restarts, failures, deadlocks, alarms, collisions, faults |
/// | `/sim/events` | `imrs.SimEvent` (JSON) | every fact the simulation measured |
/// | `/tf` | `foxglove.FrameTransforms` | where each arm link is |
/// | `/scene/cell` | `foxglove.SceneUpdate` | the conveyors, and the links' shapes (once) |
/// | `/scene/parts` | `foxglove.SceneUpdate` | pallets, feeders and their stock, the zone and who is in it |
///
/// Timestamps are the cell's clock. Off unless made: a cell with no recorder subscribes
/// nothing and pays nothing. Messages are written as they come, in compressed chunks, so
/// that memory stays bounded whatever the run's length; [`Recorder::finish`] writes the
/// summary and the index.
#[derive(Clone)]
pub struct Recorder {
    inner: Arc<Inner>,
}

struct Inner {
    path: PathBuf,
    context: Arc<Context>,
    writer: Mutex<Option<McapWriterHandle<BufWriter<File>>>>,
    /// The port and module channels, made as their first message comes, so that the same
    /// run makes them in the same order.
    topics: Mutex<HashMap<Route, Arc<RawChannel>>>,
    log: Channel<Log>,
    sim: Arc<RawChannel>,
    fixed: Channel<SceneUpdate>,
    parts: Channel<SceneUpdate>,
    tf: Channel<FrameTransforms>,
    messages: AtomicU64,
}

/// What a finished recording holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Recorded {
    /// Messages written.
    pub messages: u64,
}

impl Recorder {
    /// How often the scene is sampled while something moves, on the cell's clock, unless
    /// told otherwise: ten times a simulated second.
    pub const SCENE_PERIOD: Duration = Duration::from_millis(100);

    /// Creates (or replaces) the MCAP file at `path` and starts writing it.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, RecordError> {
        let path = path.as_ref().to_path_buf();
        let file = File::create(&path).map_err(|error| RecordError::Io {
            path: path.clone(),
            error,
        })?;
        // A context of its own: two recordings in one process never share a channel.
        let context = Context::new();
        let writer = McapWriter::new()
            .context(&context)
            .create(BufWriter::new(file))
            .map_err(|error| RecordError::Write {
                path: path.clone(),
                error: error.to_string(),
            })?;
        let json = |topic: &str, schema: &'static str, name: &str| {
            context
                .channel_builder(topic)
                .message_encoding("json")
                .schema(Schema::new(name, "jsonschema", schema.as_bytes()))
                .build_raw()
        };
        let sim = json("/sim/events", SIM_SCHEMA, "imrs.SimEvent").map_err(|error| {
            RecordError::Write {
                path: path.clone(),
                error: error.to_string(),
            }
        })?;
        let inner = Inner {
            log: context.channel_builder("/log").build(),
            sim,
            fixed: context.channel_builder("/scene/cell").build(),
            parts: context.channel_builder("/scene/parts").build(),
            tf: context.channel_builder("/tf").build(),
            topics: Mutex::new(HashMap::new()),
            writer: Mutex::new(Some(writer)),
            messages: AtomicU64::new(0),
            context,
            path,
        };
        Ok(Self {
            inner: Arc::new(inner),
        })
    }

    /// Records every event of `cell` from now on: each on its port's or its module's
    /// channel, with the text of the messages and replies of the ports that show them
    /// ([`Port::shown`](imrs_ports::Port::shown)), how long each
    /// primitive waited (the recorder turns [`Cell::observe`] on), and the events an
    /// engineer should see also on `/log`.
    pub fn record_cell(&self, cell: &Cell) {
        cell.observe(true);
        let inner = Arc::clone(&self.inner);
        cell.events().subscribe(move |event| {
            let at = nanos(event.at.since_start());
            let (route, message) = cell_message(event);
            inner.json(route, &message, at);
            if let Some(entry) = cell_log(event) {
                inner.log.log_with_time(&entry, at);
                inner.counted();
            }
        });
    }

    /// Records every fact a simulated world measures from now on, and its scene: once now,
    /// then at most every `period` of the clock while something moves. The world gives
    /// both through [`World`] (the chip line's `imrs_sim::Sim` is one).
    pub fn record_sim(&self, world: &dyn World, period: Duration) {
        let inner = Arc::clone(&self.inner);
        world.facts(Box::new(move |fact| {
            let at = nanos(fact.at);
            let message = sim_message(fact);
            inner.raw(&inner.sim, &message, at);
            if let Some(entry) = sim_log(fact) {
                inner.log.log_with_time(&entry, at);
                inner.counted();
            }
        }));
        let inner = Arc::clone(&self.inner);
        let layout = world.layout();
        let (mut moved, mut parts) = (Moved::default(), Parts::default());
        let mut first = true;
        world.watch(
            period,
            Box::new(move |scene: &Scene| {
                let at = nanos(scene.at);
                if std::mem::take(&mut first) {
                    inner.fixed.log_with_time(&scene::fixed(&layout, scene), at);
                    inner.counted();
                }
                if let Some(transforms) = moved.since_last(scene) {
                    inner.tf.log_with_time(&transforms, at);
                    inner.counted();
                }
                if let Some(update) = parts.since_last(scene) {
                    inner.parts.log_with_time(&update, at);
                    inner.counted();
                }
            }),
        );
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.inner.path
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.inner.messages.load(Ordering::Relaxed)
    }

    /// Writes the summary and the index and closes the file. Messages that come after are
    /// dropped. Finishing twice is an error naming the file.
    pub fn finish(&self) -> Result<Recorded, RecordError> {
        let writer = lock(&self.inner.writer).take();
        let Some(writer) = writer else {
            return Err(RecordError::Write {
                path: self.inner.path.clone(),
                error: "the recording was already finished".into(),
            });
        };
        let file = writer.close().map_err(|error| RecordError::Write {
            path: self.inner.path.clone(),
            error: error.to_string(),
        })?;
        file.into_inner()
            .map_err(|error| RecordError::Io {
                path: self.inner.path.clone(),
                error: error.into_error(),
            })?
            .sync_all()
            .map_err(|error| RecordError::Io {
                path: self.inner.path.clone(),
                error,
            })?;
        Ok(Recorded {
            messages: self.messages(),
        })
    }
}

impl Inner {
    fn json(&self, route: Route, message: &Value, at: u64) {
        let mut topics = lock(&self.topics);
        let channel = match topics.get(&route) {
            Some(channel) => Arc::clone(channel),
            None => {
                let (topic, schema, name) = route.channel();
                let made = self
                    .context
                    .channel_builder(topic)
                    .message_encoding("json")
                    .schema(Schema::new(name, "jsonschema", schema.as_bytes()))
                    .build_raw();
                let Ok(channel) = made else {
                    // The only refusal is a missing encoding, given above.
                    return;
                };
                topics.insert(route, Arc::clone(&channel));
                channel
            }
        };
        drop(topics);
        self.raw(&channel, message, at);
    }

    fn raw(&self, channel: &RawChannel, message: &Value, at: u64) {
        let bytes = message.to_string();
        channel.log_with_meta(
            bytes.as_bytes(),
            foxglove::PartialMetadata { log_time: Some(at) },
        );
        self.counted();
    }

    fn counted(&self) {
        self.messages.fetch_add(1, Ordering::Relaxed);
    }
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("path", &self.inner.path)
            .field("messages", &self.messages())
            .finish_non_exhaustive()
    }
}

fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // Each use is one short block that leaves the map or the writer whole.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}
