//! The coordinator module itself: it serves its ports from the zone table's bookkeeping and
//! the robots' told positions, wakes sleepers, resolves deadlocks, passes alarms on, and
//! logs what it did.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex, PoisonError};

use imrs_core::ModuleSpec;
use imrs_ports::{End, Name, select, usage};

use super::messages::{Geometry, Message, Seen, Wake};
use super::ports::CoordinatorPorts;
use crate::zones::{Answer, Deadlock, DeadlockKind, Positions, Resources, ZoneError};

/// How far to the side an alternative trajectory may go.
pub const ALTERNATIVE_REACH: f32 = 0.25;

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
