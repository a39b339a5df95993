//! The simulation: the world, the stepper that moves it on the framework clock, and what
//! the handles through which modules drive its devices ask of it. Each device's file
//! hands its handle out (`Sim::robot`, `Sim::gate`, `Sim::relay`): a handle holds the
//! simulation, so the simulation names no device.

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use imrs_ports::{Instant, SharedClock};
use tokio::sync::Notify;
use tokio::sync::futures::Notified;

use crate::event::{SimEvent, SimEventKind, SimLog};
use crate::fault::Fault;
use crate::ids::{FeederId, Line, PalletId, RobotId};
use crate::layout::STEP;
use crate::scene::Scene;
use crate::step::next_step_after;
use crate::world::{RobotTimes, World};

/// How the cell is set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SimConfig {
    /// Seeds every random choice (feeder stocks).
    pub seed: u64,
    /// The feeders' stocks, or `None` to draw them from the seed (150 to 250 chips each).
    pub stocks: Option<[u32; 4]>,
}

impl SimConfig {
    /// The cell for `seed`.
    pub fn seeded(seed: u64) -> Self {
        Self { seed, stocks: None }
    }
}

/// The simulated cell. Cheap to clone: every clone drives the same world.
#[derive(Clone)]
pub struct Sim {
    shared: Arc<Shared>,
}

struct Shared {
    world: Mutex<World>,
    clock: SharedClock,
    activity: Notify,
    /// Wakes everyone waiting for the world to change, after every step. (Not a `watch`
    /// channel: its waiters are woken in a random order, and runs must be reproducible.)
    stepped: Notify,
    log: SimLog,
    watchers: Mutex<Vec<Watcher>>,
    /// Whether anyone watches: read at every step, so that an unwatched world takes no lock.
    watched: AtomicBool,
    /// Each robot's turn: a robot does one thing at a time, whoever drives it.
    turns: [tokio::sync::Mutex<()>; 6],
}

/// Someone who draws the scene, at most once per `period` of the clock.
struct Watcher {
    period: Duration,
    next: Instant,
    see: Box<dyn FnMut(&Scene) + Send>,
}

impl Sim {
    /// A cell set up by `config`, on `clock`. Nothing moves until [`Sim::run`] runs.
    pub fn new(config: SimConfig, clock: SharedClock) -> Self {
        Self {
            shared: Arc::new(Shared {
                world: Mutex::new(World::new(config.seed, config.stocks)),
                clock,
                activity: Notify::new(),
                stepped: Notify::new(),
                log: SimLog::default(),
                watchers: Mutex::new(Vec::new()),
                watched: AtomicBool::new(false),
                turns: Default::default(),
            }),
        }
    }

    /// The stepper: steps the world every [`STEP`](crate::layout::STEP) of the clock while
    /// anything moves, and sleeps while nothing does. Spawn it once.
    pub async fn run(self) {
        let clock = Arc::clone(&self.shared.clock);
        let mut last = None;
        loop {
            if !self.world().is_active() {
                self.shared.activity.notified().await;
            }
            let now = clock.now().max(last.unwrap_or(Instant::ZERO));
            let next = next_step_after(now, STEP);
            clock.sleep_until(next).await;
            let events = self.world().step(next);
            last = Some(next);
            events
                .into_iter()
                .for_each(|event| self.shared.log.record(event));
            self.tell_watchers(next);
            self.shared.stepped.notify_waiters();
        }
    }

    /// The cell as rapier has it now.
    pub fn scene(&self) -> Scene {
        let now = self.now();
        self.world().scene(now)
    }

    /// Calls `see` with the scene now, then after steps of the world: at most once per
    /// `period` of the clock while something moves (a zero period: after every step), and
    /// after the step at which everything stopped. The world steps only while something
    /// moves, so a still cell costs its watchers nothing: the last scene they saw is still
    /// true.
    pub fn watch(&self, period: Duration, mut see: impl FnMut(&Scene) + Send + 'static) {
        let scene = self.scene();
        see(&scene);
        lock(&self.shared.watchers).push(Watcher {
            period,
            next: scene.at + period,
            see: Box::new(see),
        });
        self.shared.watched.store(true, Ordering::Release);
    }

    fn tell_watchers(&self, now: Instant) {
        if !self.shared.watched.load(Ordering::Acquire) {
            return;
        }
        let mut watchers = lock(&self.shared.watchers);
        let (scene, still) = {
            let world = self.world();
            let still = !world.is_active();
            if !still && watchers.iter().all(|watcher| watcher.next > now) {
                return;
            }
            (world.scene(now), still)
        };
        for watcher in watchers
            .iter_mut()
            .filter(|watcher| still || watcher.next <= now)
        {
            (watcher.see)(&scene);
            watcher.next = now + watcher.period;
        }
    }

    /// Spawns [`Sim::run`] on the current tokio runtime.
    pub fn spawn(&self) -> tokio::task::JoinHandle<()> {
        tokio::spawn(self.clone().run())
    }

    /// Injects `fault`, to strike at its time.
    pub fn inject(&self, fault: Fault) {
        self.world().inject(fault);
        self.shared.activity.notify_one();
    }

    /// The measured facts of the run.
    pub fn log(&self) -> &SimLog {
        &self.shared.log
    }

    /// The time now, on the simulation's clock.
    pub fn now(&self) -> Instant {
        self.shared.clock.now()
    }

    /// The simulation's clock.
    pub fn clock(&self) -> &SharedClock {
        &self.shared.clock
    }

    /// Every pallet on the conveyors, with its position as rapier has it.
    pub fn pallets(&self) -> Vec<(Line, PalletId, [f32; 3])> {
        self.world().pallet_positions()
    }

    /// The closest two arms' links came while both were in the feeder zone, in metres, as
    /// rapier measured them at each step; `None` if never two were in it together.
    pub fn closest_in_zone(&self) -> Option<f32> {
        self.world().closest_in_zone
    }

    /// How each robot spent its time so far, as measured by the simulation.
    pub fn robot_times(&self) -> Vec<(RobotId, RobotTimes)> {
        self.world().robot_times()
    }

    /// Each feeder's chip number and the chips it has left.
    pub fn feeders(&self) -> Vec<(FeederId, u32, u32)> {
        self.world()
            .feeders
            .iter()
            .map(|feeder| (feeder.id, feeder.chip, feeder.stock))
            .collect()
    }

    /// Runs `change` on the world at the current time, then records the events it made.
    pub(crate) fn with<R>(&self, change: impl FnOnce(&mut World, Instant) -> R) -> R {
        let now = self.now();
        let (result, events) = {
            let mut world = self.world();
            let result = change(&mut world, now);
            (result, world.take_pending())
        };
        events
            .into_iter()
            .for_each(|event| self.shared.log.record(event));
        result
    }

    /// Waits for `robot`'s turn: until what it is doing is done.
    pub(crate) async fn turn(&self, robot: RobotId) -> tokio::sync::MutexGuard<'_, ()> {
        self.shared.turns[robot.index()].lock().await
    }

    /// Takes off `line` every pallet its stations hold, as scrap: a line whose controller
    /// died left them in a state nobody knows. Returns them.
    pub fn scrap_held(&self, line: Line) -> Vec<PalletId> {
        let scrapped = self.with(|world, _| world.scrap_held(line));
        let at = self.now();
        for &pallet in &scrapped {
            self.record(SimEvent {
                at,
                kind: SimEventKind::PalletScrapped { line, pallet },
            });
        }
        self.wake_stepper();
        scrapped
    }

    pub(crate) fn record(&self, event: SimEvent) {
        self.shared.log.record(event);
    }

    /// Tells the stepper that something started moving.
    pub(crate) fn wake_stepper(&self) {
        self.shared.activity.notify_one();
    }

    /// A future that completes after the next step; enable it before looking at the world.
    pub(crate) fn next_step(&self) -> Notified<'_> {
        self.shared.stepped.notified()
    }

    fn world(&self) -> MutexGuard<'_, World> {
        // Every change to the world is a short synchronous block that leaves it consistent.
        self.shared
            .world
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }
}

fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // A watcher that panicked leaves the list as it was: still whole.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

impl fmt::Debug for Sim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Sim")
            .field("now", &self.now())
            .finish_non_exhaustive()
    }
}
