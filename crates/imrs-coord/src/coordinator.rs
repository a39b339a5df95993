//! The zone coordinator as a module (Jiménez et al. 1992, centralized loose coordination), speaking
//! the seed's message set over typed ports.
//!
//! | seed | port | from → to |
//! |---|---|---|
//! | request to move in a shared zone; position (stopped inside); zone release; trajectory end | `TO_COORDINATOR`, a [`Message`], answered [`Answer::Grant`] or [`Answer::Sleep`] | robot → coordinator |
//! | position information (where its links are); a trajectory's next points to check against the other robots; an alternative trajectory round the robots in the way | `SPACE`, a [`Geometry`], answered with what the coordinator [`Seen`] | robot → coordinator |
//! | alarm | `ALARM` (priority 1: served before everything else) | robot → coordinator |
//! | wake up (and back off, to resolve a deadlock) | `WAKE_<ROBOT>`, a [`Wake`] | coordinator → robot |
//! | alarm: an emergency stop reaches every robot | `EMERGENCY`, a `sendall` | coordinator → every robot |
//!
//! After every sleep it looks for deadlocks among the robots asleep, over exclusive zones,
//! tools and rights to move in shared zones; each victim is told to back off. A way it
//! finds blocked by a robot asleep at a border that waits for what the blocked robot holds
//! is a deadlock too, of space and zones, once the blocked robot says it waits
//! ([`RobotLink::wait_on`]): the sleeper is told to back off. A robot's way is checked
//! against the other robots where *they said* they were ([`Positions`]): the coordinator
//! knows no more of the cell than its messages told it.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex, PoisonError};

use imrs_core::prelude::*;
use imrs_ports::{AnyUser, End, Name, Port, PortSpec, SharedClock, select, usage};

use crate::zones::{Answer, Deadlock, DeadlockKind, Pose, Positions, Resources, Sweep, ZoneError};

/// What a robot tells the coordinator.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Message {
    /// Request to move in a zone (or to take a tool).
    Request(Name),
    /// Request to move in a zone (or to take a tool) from inside these shared zones, in
    /// which it moves: if it must sleep at the border, it stops and gives up its right to
    /// move in each, as a position message would say, in the same message.
    RequestGivingUp(Name, Vec<Name>),
    /// Stopped inside this zone, away from the trajectory's end point.
    Position(Name),
    /// Left this zone (or put this tool down).
    Release(Name),
    /// The trajectory has ended: the robot is stopped.
    TrajectoryEnd,
}

/// What a robot tells or asks the coordinator about space.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// Position information: its links are here now.
    At(Pose),
    /// Its links at the next points of its trajectory: do they keep clear of every other
    /// robot?
    Check(Sweep),
    /// Its links at the next points of its trajectory, where it waits, stopped, holding
    /// only what it is in: do they keep clear of every other robot? As [`Geometry::Check`];
    /// and a robot asleep in the way that waits for what this one holds is told to back
    /// off (a deadlock of space and zones).
    Wait(Sweep),
    /// Its straight way from `from` to `to` is blocked by the robots `around`: an
    /// alternative trajectory round them.
    Alternative {
        /// Where the tool is.
        from: [f32; 2],
        /// Where it goes.
        to: [f32; 2],
        /// The robots in the way.
        around: Vec<Name>,
    },
}

/// What the coordinator answers about space.
#[derive(Debug, Clone, PartialEq)]
pub enum Seen {
    /// The position is noted.
    Noted,
    /// The way is clear of every other robot: continue.
    Clear,
    /// These robots are in the way, where they last said they were.
    Blocked(Vec<Name>),
    /// Continue with this alternative trajectory (the whole way, its start first), or, if
    /// `None`, there is none within reach.
    Alternative(Option<Vec<[f32; 2]>>),
}

/// How far to the side an alternative trajectory may go.
pub const ALTERNATIVE_REACH: f32 = 0.25;

/// What the coordinator tells a sleeping robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wake {
    /// The resource it slept on may be free: ask again.
    WakeUp,
    /// It is the victim of a deadlock: it waits for nothing any more. It gets out of the
    /// zones it is in and puts down the tool it holds, says so (each a release: the books
    /// keep them its own until then), and asks again later.
    BackOff,
}

/// How many robots a coordinator's ports admit.
pub const MAX_ROBOTS: usize = 16;

/// The coordinator's ports. Declare them, give each robot its [`RobotLink`], and start
/// [`coordinator`].
#[derive(Clone)]
pub struct CoordinatorPorts {
    /// `TO_COORDINATOR`: requests, positions, releases, trajectory ends.
    pub to_coordinator:
        Port<(Name, Message), Result<Answer, String>, usage::Receive, AnyUser, MAX_ROBOTS>,
    /// `SPACE`: positions, checks of the way ahead, alternative trajectories.
    pub space: Port<(Name, Geometry), Result<Seen, String>, usage::Receive, AnyUser, MAX_ROBOTS>,
    /// `ALARM`.
    pub alarm: Port<(Name, String), (), usage::Receive, AnyUser, MAX_ROBOTS>,
    /// `EMERGENCY`: the emergency stop, to every robot.
    pub emergency: Port<String, (), usage::SendAll, AnyUser, MAX_ROBOTS>,
    /// `WAKE_<ROBOT>`, one per robot.
    pub wake: BTreeMap<Name, Port<Wake, (), usage::Send>>,
}

impl CoordinatorPorts {
    /// The ports of a coordinator named `name` for `robots`, on `clock`.
    pub fn new(name: &str, robots: &[&str], clock: &SharedClock) -> Self {
        let spec = |port: String| PortSpec::new(port, name).clock(clock.clone());
        Self {
            to_coordinator: Port::new(spec("TO_COORDINATOR".into()).priority(2)),
            space: Port::new(spec("SPACE".into()).priority(2)),
            alarm: Port::new(spec("ALARM".into()).priority(1)),
            emergency: Port::new(spec("EMERGENCY".into()).priority(1)),
            wake: robots
                .iter()
                .map(|&robot| {
                    let port = Port::new(spec(format!("WAKE_{robot}")).user_list([robot]));
                    (Name::from(robot), port)
                })
                .collect(),
        }
    }

    /// Declares every port to `cell`, so that the cell checks their wiring and lists them
    /// ([`Cell::ports`]).
    pub fn declare_to(&self, cell: &Cell) -> Result<(), imrs_ports::WireError> {
        cell.declare(&self.to_coordinator)?;
        cell.declare(&self.space)?;
        cell.declare(&self.alarm)?;
        cell.declare(&self.emergency)?;
        self.wake.values().try_for_each(|port| cell.declare(port))
    }

    /// Robot `robot`'s ends of the ports.
    pub fn link(&self, robot: &str) -> Result<RobotLink, imrs_ports::WireError> {
        let wake = self.wake.get(&Name::from(robot)).ok_or_else(|| {
            imrs_ports::WireError::NotOnUserList {
                port: format!("WAKE_{robot}").into(),
                module: robot.into(),
            }
        })?;
        Ok(RobotLink {
            robot: robot.into(),
            to: self.to_coordinator.user_named(robot)?,
            space: self.space.user_named(robot)?,
            alarm: self.alarm.user_named(robot)?,
            wake: wake.user_named(robot)?,
            emergency: self.emergency.user_named(robot)?,
        })
    }
}

/// Why a robot could not have a zone.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refused {
    /// It must back off: it was chosen to resolve a deadlock.
    BackOff,
    /// The coordinator could not be reached, or refused the name.
    Failed(String),
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BackOff => f.write_str("told to back off, the victim of a deadlock"),
            Self::Failed(why) => f.write_str(why),
        }
    }
}

impl std::error::Error for Refused {}

/// A wake-up received, or why none could be.
type Woken = Result<(Wake, imrs_ports::ReplyHandle<()>), imrs_ports::ReceiveError>;

/// Sends `request` on `to` while listening for a wake-up on `wake`, for a robot asleep in
/// the coordinator's books: `None` once the coordinator answered (an answer counts even if
/// the wake-up came as well: the coordinator has acted on it), or the wake-up if it came
/// first, the request withdrawn.
async fn listening<Q: Send + 'static, A: Send + 'static>(
    to: &mut End<(Name, Q), Result<A, String>, usage::Send>,
    wake: &mut End<Wake, (), usage::Receive>,
    request: (Name, Q),
) -> Result<Option<Woken>, Refused> {
    tokio::select! {
        biased;
        told = to.send(request) => {
            told
                .map_err(|error| Refused::Failed(error.to_string()))?
                .map_err(Refused::Failed)?;
            Ok(None)
        }
        woken = wake.receive() => Ok(Some(woken)),
    }
}

/// A robot's ends of the coordinator's ports.
pub struct RobotLink {
    robot: Name,
    to: End<(Name, Message), Result<Answer, String>, usage::Send>,
    space: End<(Name, Geometry), Result<Seen, String>, usage::Send>,
    alarm: End<(Name, String), (), usage::Send>,
    wake: End<Wake, (), usage::Receive>,
    emergency: End<String, (), usage::Receive>,
}

impl RobotLink {
    /// Tells the coordinator `message`; its answer.
    pub async fn tell(&mut self, message: Message) -> Result<Answer, Refused> {
        self.to
            .send((self.robot.clone(), message))
            .await
            .map_err(|error| Refused::Failed(error.to_string()))?
            .map_err(Refused::Failed)
    }

    /// Asks for `zone` (or a tool) until granted, sleeping at the border meanwhile.
    pub async fn acquire(&mut self, zone: &str) -> Result<(), Refused> {
        self.acquire_giving_up(zone, &[]).await.map(drop)
    }

    /// Asks for `zone` (or a tool) until granted, as [`acquire`](Self::acquire) does; but
    /// the robot moves in the shared zones `moving_in`, and if it must sleep at the border,
    /// it first gives up its right to move in each of them, with a position message (it is
    /// stopped inside): the seed's reason why shared zones cannot deadlock. Returns the
    /// zones it gave up, for it to ask again before it moves.
    pub async fn acquire_giving_up(
        &mut self,
        zone: &str,
        moving_in: &[Name],
    ) -> Result<Vec<Name>, Refused> {
        let mut given_up: Vec<Name> = Vec::new();
        loop {
            // One message: the coordinator never waits on a robot that is still telling it
            // something (its wake-ups are rendezvous).
            let giving_up: Vec<Name> = moving_in
                .iter()
                .filter(|shared| !given_up.contains(shared))
                .cloned()
                .collect();
            let request = Message::RequestGivingUp(zone.into(), giving_up.clone());
            match self.tell(request).await? {
                Answer::Grant => return Ok(given_up),
                Answer::Sleep => {
                    given_up.extend(giving_up);
                    let (wake, reply) = self
                        .wake
                        .receive()
                        .await
                        .map_err(|error| Refused::Failed(error.to_string()))?;
                    reply.reply(());
                    if wake == Wake::BackOff {
                        return Err(Refused::BackOff);
                    }
                }
            }
        }
    }

    /// Asks for `zone` (or a tool) while the robot moves, as its pipeline asks for a point
    /// ahead; granted, it goes on. Told to sleep, it stops (each call of `braking` halts it
    /// and resolves after a step, to where its links are then, if it can say, and whether
    /// it stands still; each pose is told as it brakes): an arm cannot stop at once, and
    /// keeps its right to move in the shared zones `moving_in` while it brakes in them.
    /// Stopped, it tells where it is (position information), gives each right up with a
    /// position message, as the seed's robot does, waits to be woken, and asks again.
    /// Returns the zones it gave up, for it to ask again before it moves.
    ///
    /// From the sleep until the wake-up, every message it sends is sent while it listens for
    /// the wake-up: the coordinator waits for a robot it wakes, and one that waited for the
    /// coordinator in turn would leave both waiting.
    pub async fn acquire_stopping<F: Future<Output = (Option<Pose>, bool)>>(
        &mut self,
        zone: &str,
        moving_in: &[Name],
        mut braking: impl FnMut() -> F,
    ) -> Result<Vec<Name>, Refused> {
        let mut given_up: Vec<Name> = Vec::new();
        let mut at_rest = false;
        loop {
            let giving_up: Vec<Name> = if at_rest {
                moving_in
                    .iter()
                    .filter(|shared| !given_up.contains(shared))
                    .cloned()
                    .collect()
            } else {
                Vec::new()
            };
            let request = Message::RequestGivingUp(zone.into(), giving_up.clone());
            if self.tell(request).await? == Answer::Grant {
                return Ok(given_up);
            }
            given_up.extend(giving_up);
            let woken = if at_rest {
                self.wake.receive().await
            } else {
                self.brake_asleep(&mut braking, moving_in, &mut given_up, &mut at_rest)
                    .await?
            };
            let (wake, reply) = woken.map_err(|error| Refused::Failed(error.to_string()))?;
            reply.reply(());
            if wake == Wake::BackOff {
                return Err(Refused::BackOff);
            }
        }
    }

    /// Asleep and braking: each step of `braking` (where its links are after it, and
    /// whether it stands still) told as position information, listening for the wake-up
    /// meanwhile; once it stands still, its rights given up. The wake-up.
    async fn brake_asleep<F: Future<Output = (Option<Pose>, bool)>>(
        &mut self,
        braking: &mut impl FnMut() -> F,
        moving_in: &[Name],
        given_up: &mut Vec<Name>,
        at_rest: &mut bool,
    ) -> Result<Woken, Refused> {
        loop {
            let step = braking();
            let (pose, still) = tokio::select! {
                biased;
                woken = self.wake.receive() => return Ok(woken),
                braked = step => braked,
            };
            if still {
                *at_rest = true;
                return self.give_up_stopped(pose, moving_in, given_up).await;
            }
            if let Some(pose) = pose {
                let at = (self.robot.clone(), Geometry::At(pose));
                if let Some(woken) = listening(&mut self.space, &mut self.wake, at).await? {
                    return Ok(woken);
                }
            }
        }
    }

    /// Stopped while asleep at `pose`: tells where it is, and gives up the right to move in
    /// each of `moving_in`, a position message each, listening for the wake-up meanwhile
    /// ([`listening`]); then waits for it.
    async fn give_up_stopped(
        &mut self,
        pose: Option<Pose>,
        moving_in: &[Name],
        given_up: &mut Vec<Name>,
    ) -> Result<Woken, Refused> {
        if let Some(pose) = pose {
            let at = (self.robot.clone(), Geometry::At(pose));
            if let Some(woken) = listening(&mut self.space, &mut self.wake, at).await? {
                return Ok(woken);
            }
        }
        for shared in moving_in {
            let position = (self.robot.clone(), Message::Position(shared.clone()));
            if let Some(woken) = listening(&mut self.to, &mut self.wake, position).await? {
                return Ok(woken);
            }
            given_up.push(shared.clone());
        }
        Ok(self.wake.receive().await)
    }

    /// Asks the coordinator about space; its answer.
    async fn ask(&mut self, geometry: Geometry) -> Result<Seen, Refused> {
        self.space
            .send((self.robot.clone(), geometry))
            .await
            .map_err(|error| Refused::Failed(error.to_string()))?
            .map_err(Refused::Failed)
    }

    /// Tells the coordinator where its links are now (position information).
    pub async fn at(&mut self, pose: Pose) -> Result<(), Refused> {
        self.ask(Geometry::At(pose)).await.map(drop)
    }

    /// The robots in the way of its links at the next points of its trajectory, where they
    /// last told the coordinator they were: none when the way is clear.
    pub async fn check(&mut self, sweep: Sweep) -> Result<Vec<Name>, Refused> {
        match self.ask(Geometry::Check(sweep)).await? {
            Seen::Blocked(robots) => Ok(robots),
            Seen::Clear => Ok(Vec::new()),
            other => Err(Refused::Failed(format!("a check answered {other:?}"))),
        }
    }

    /// As [`check`](Self::check), for a robot stopped and waiting for its way to clear,
    /// holding only what it is in: a robot asleep in its way that waits for what it holds
    /// is told to back off.
    pub async fn wait_on(&mut self, sweep: Sweep) -> Result<Vec<Name>, Refused> {
        match self.ask(Geometry::Wait(sweep)).await? {
            Seen::Blocked(robots) => Ok(robots),
            Seen::Clear => Ok(Vec::new()),
            other => Err(Refused::Failed(format!("a wait answered {other:?}"))),
        }
    }

    /// The coordinator's alternative trajectory from `from` to `to` round the robots
    /// `around`: the whole way, `from` first, or `None` if there is none.
    pub async fn alternative(
        &mut self,
        from: [f32; 2],
        to: [f32; 2],
        around: Vec<Name>,
    ) -> Result<Option<Vec<[f32; 2]>>, Refused> {
        match self.ask(Geometry::Alternative { from, to, around }).await? {
            Seen::Alternative(way) => Ok(way),
            other => Err(Refused::Failed(format!(
                "an alternative answered {other:?}"
            ))),
        }
    }

    /// Raises an alarm: the coordinator stops every robot.
    pub async fn alarm(&mut self, text: impl Into<String>) -> Result<(), Refused> {
        self.alarm
            .send((self.robot.clone(), text.into()))
            .await
            .map_err(|error| Refused::Failed(error.to_string()))
    }

    /// Waits for an emergency stop; its text.
    pub async fn emergency(&mut self) -> Result<String, Refused> {
        let (text, reply) = self
            .emergency
            .receive()
            .await
            .map_err(|error| Refused::Failed(error.to_string()))?;
        reply.reply(());
        Ok(text)
    }
}

/// What the coordinator did, for a cell's report.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CoordinatorLog {
    /// Requests granted at once.
    pub granted: u32,
    /// Requests answered with sleep.
    pub slept: u32,
    /// Deadlocks among zones, tools and rights to move found and resolved: each cycle,
    /// what it ran through and its victim.
    pub deadlocks: Vec<Deadlock>,
    /// Deadlocks of space and zones found and resolved, each with its victim and what the
    /// victim waited on (through the sleepers): a robot asleep at a border in the way of one
    /// that holds what it waits for, told to back off.
    pub in_the_way: Vec<(Name, DeadlockKind)>,
    /// Alarms, each passed on to every robot.
    pub alarms: Vec<(Name, String)>,
    /// Messages it could not take (unknown zone or robot), named.
    pub refused: Vec<String>,
    /// Ways ahead it checked against the robots' told positions.
    pub checked: u32,
    /// Of those, ways it found blocked by another robot.
    pub blocked: u32,
    /// Alternative trajectories it computed, and of those, how many it found.
    pub alternatives: (u32, u32),
}

impl CoordinatorLog {
    /// Deadlocks found and resolved, of either sort: each has had its victim told to back
    /// off.
    pub fn resolved(&self) -> usize {
        self.deadlocks.len() + self.in_the_way.len()
    }
}

/// The coordinator module `name`: answers every message from `table`'s bookkeeping and the
/// robots' told `positions`, wakes sleepers, resolves deadlocks, and passes alarms on to
/// every robot. Its log is shared.
pub fn coordinator(
    name: &str,
    table: Resources,
    positions: Positions,
    ports: &CoordinatorPorts,
    log: Arc<Mutex<CoordinatorLog>>,
) -> ModuleSpec<()> {
    let ports = ports.clone();
    let table = Arc::new(Mutex::new(table));
    let positions = Arc::new(Mutex::new(positions));
    ModuleSpec::new(name, ()).task(name, move |_ctx| {
        let (ports, table, log) = (ports.clone(), Arc::clone(&table), Arc::clone(&log));
        let positions = Arc::clone(&positions);
        async move {
            let mut to = ports.to_coordinator.owner()?;
            let mut space = ports.space.owner()?;
            let mut alarm = ports.alarm.owner()?;
            let mut emergency = ports.emergency.owner()?;
            let mut wake: BTreeMap<Name, End<Wake, (), usage::Send>> = BTreeMap::new();
            for (robot, port) in &ports.wake {
                wake.insert(robot.clone(), port.owner()?);
            }
            // The robots told to sleep and not woken since. A wake-up is a rendezvous, and
            // a robot woken once is on its way to ask again, not waiting for another: one
            // sent to it then would wait for it while it waits to be heard.
            let mut asleep: BTreeSet<Name> = BTreeSet::new();
            loop {
                enum Event {
                    Alarm(Name, String),
                    Message(
                        Name,
                        Message,
                        imrs_ports::ReplyHandle<Result<Answer, String>>,
                    ),
                    Space(
                        Name,
                        Geometry,
                        imrs_ports::ReplyHandle<Result<Seen, String>>,
                    ),
                }
                let event = select()
                    .or(&mut alarm, |((robot, text), reply)| {
                        reply.reply(());
                        Event::Alarm(robot, text)
                    })
                    .or(&mut to, |((robot, message), reply)| {
                        Event::Message(robot, message, reply)
                    })
                    .or(&mut space, |((robot, geometry), reply)| {
                        Event::Space(robot, geometry, reply)
                    })
                    .await?;
                match event {
                    Event::Space(robot, geometry, reply) => {
                        let waits = matches!(geometry, Geometry::Wait(_));
                        let seen = see(&mut lock(&positions), &mut lock(&log), &robot, geometry);
                        if let Err(error) = &seen {
                            lock(&log).refused.push(error.to_string());
                        }
                        // A robot asleep at a border, in the way of one that holds what it
                        // waits for: neither can go on. The sleeper is the victim: stopped
                        // and waiting for nothing else, it can get out of the way.
                        let victims: Vec<Name> = match &seen {
                            Ok(Seen::Blocked(blocking)) if waits => {
                                let table = lock(&table);
                                blocking
                                    .iter()
                                    .filter(|other| asleep.contains(*other))
                                    .filter(|other| {
                                        let waits =
                                            table.waits_on(other.as_str(), robot.as_str(), |r| {
                                                asleep.contains(r)
                                            });
                                        waits.is_some()
                                    })
                                    .cloned()
                                    .collect()
                            }
                            _ => Vec::new(),
                        };
                        reply.reply(seen.map_err(|error| error.to_string()));
                        for victim in victims {
                            // One woken by a victim before it waits for nothing any more.
                            let still = asleep.contains(&victim).then(|| {
                                lock(&table).waits_on(victim.as_str(), robot.as_str(), |r| {
                                    asleep.contains(r)
                                })
                            });
                            let Some(Some(kind)) = still else {
                                continue;
                            };
                            let woken = lock(&table)
                                .stop_sleeping(victim.as_str())
                                .unwrap_or_default();
                            lock(&log).in_the_way.push((victim.clone(), kind));
                            wake_up(&mut wake, &mut asleep, &victim, Wake::BackOff).await;
                            for robot in woken {
                                wake_up(&mut wake, &mut asleep, &robot, Wake::WakeUp).await;
                            }
                        }
                    }
                    Event::Alarm(robot, text) => {
                        lock(&log).alarms.push((robot.clone(), text.clone()));
                        // Every robot that takes it stops; one that does not is not waited for.
                        let _ = emergency.send_all(format!("{robot}: {text}")).await;
                    }
                    Event::Message(robot, message, reply) => {
                        let answered = answer(&mut lock(&table), &robot, &message);
                        let (answer, woken) = match answered {
                            Ok(answered) => answered,
                            Err(error) => {
                                // Refused by name: the robot hears what was wrong.
                                lock(&log).refused.push(error.to_string());
                                reply.reply(Err(error.to_string()));
                                continue;
                            }
                        };
                        match answer {
                            Answer::Grant => lock(&log).granted += 1,
                            Answer::Sleep => {
                                lock(&log).slept += 1;
                                asleep.insert(robot.clone());
                            }
                        }
                        reply.reply(Ok(answer));
                        for robot in woken {
                            wake_up(&mut wake, &mut asleep, &robot, Wake::WakeUp).await;
                        }
                        // Every cycle among the robots asleep, each resolved in turn. A robot
                        // already woken waits for nothing yet: it is looked at again when it
                        // sleeps.
                        let mut look = answer == Answer::Sleep;
                        while look {
                            // The table's lock ends with this statement, before any wake-up.
                            let found = lock(&table).deadlock_among(|r| asleep.contains(r));
                            look = found.is_some();
                            let Some(deadlock) = found else {
                                break;
                            };
                            let woken = lock(&table).resolve(&deadlock).unwrap_or_default();
                            lock(&log).deadlocks.push(deadlock.clone());
                            let victim = &deadlock.victim;
                            // The victim leaves `asleep` here, so the loop ends.
                            wake_up(&mut wake, &mut asleep, victim, Wake::BackOff).await;
                            for robot in woken {
                                wake_up(&mut wake, &mut asleep, &robot, Wake::WakeUp).await;
                            }
                        }
                    }
                }
            }
        }
    })
}

/// Wakes `robot` with `why`, if it sleeps: a robot already woken is not waited for again.
async fn wake_up(
    wake: &mut BTreeMap<Name, End<Wake, (), usage::Send>>,
    asleep: &mut BTreeSet<Name>,
    robot: &Name,
    why: Wake,
) {
    if asleep.remove(robot)
        && let Some(end) = wake.get_mut(robot)
    {
        let _ = end.send(why).await;
    }
}

/// The answer to one question about space, from the robots' told positions; a position
/// told is noted.
fn see(
    positions: &mut Positions,
    log: &mut CoordinatorLog,
    robot: &Name,
    geometry: Geometry,
) -> Result<Seen, ZoneError> {
    let robot = robot.as_str();
    Ok(match geometry {
        Geometry::At(pose) => {
            positions.tell(robot, pose)?;
            Seen::Noted
        }
        Geometry::Check(sweep) | Geometry::Wait(sweep) => {
            log.checked += 1;
            let blocking = positions.blockers(robot, &sweep)?;
            if blocking.is_empty() {
                Seen::Clear
            } else {
                log.blocked += 1;
                Seen::Blocked(blocking)
            }
        }
        Geometry::Alternative { from, to, around } => {
            let way = positions.alternative(robot, from, to, &around, ALTERNATIVE_REACH)?;
            log.alternatives.0 += 1;
            log.alternatives.1 += u32::from(way.is_some());
            Seen::Alternative(way)
        }
    })
}

/// The table's answer to a request for `zone` (or a tool).
fn request(table: &mut Resources, robot: &str, zone: &Name) -> Result<Answer, ZoneError> {
    if table.is_tool(zone.as_str()) {
        table.request_tool(robot, zone.as_str())
    } else {
        table.request_move(robot, zone.as_str())
    }
}

/// The table's answer to one message, and who it wakes.
fn answer(
    table: &mut Resources,
    robot: &Name,
    message: &Message,
) -> Result<(Answer, Vec<Name>), ZoneError> {
    let robot = robot.as_str();
    Ok(match message {
        Message::Request(zone) => (request(table, robot, zone)?, Vec::new()),
        Message::RequestGivingUp(zone, moving_in) => {
            // Every zone given up is checked before anything changes: a request refused
            // halfway would leave the robot queued with nobody to wake it.
            for shared in moving_in {
                table.check_zone(shared.as_str())?;
            }
            let answer = request(table, robot, zone)?;
            let mut woken = Vec::new();
            if answer == Answer::Sleep {
                for shared in moving_in {
                    woken.extend(table.stopped_inside(robot, shared.as_str())?);
                }
            }
            (answer, woken)
        }
        Message::Position(zone) => (Answer::Grant, table.stopped_inside(robot, zone.as_str())?),
        Message::Release(zone) => {
            let woken = if table.is_tool(zone.as_str()) {
                table.release_tool(robot, zone.as_str())?
            } else {
                table.release(robot, zone.as_str())?
            };
            (Answer::Grant, woken)
        }
        Message::TrajectoryEnd => {
            table.trajectory_end(robot)?;
            (Answer::Grant, Vec::new())
        }
    })
}

fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    // Each critical section is a few field updates: a panic cannot leave it half-changed.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}
