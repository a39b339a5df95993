//! An arm of the table cell as a module: it asks the scheduler for work, and carries each
//! job out through the coordinator — its trajectory's points checked ahead in the
//! pipeline (zones requested before the arm reaches them, released once it has left them),
//! its position told after every step, and its links at the next points checked by the
//! coordinator, against where the other arms told it they are, before every step. An arm
//! holds its own arm of the table and nothing else of it: it cannot see another arm but
//! through the coordinator.
//!
//! The seed's messages between an arm's two controllers, here:
//!
//! | seed | here |
//! |---|---|
//! | TRAJECTORY | a straight leg, its points spaced 2 cm |
//! | TRAJECTORY_POINT (check a point) | [`Pipeline::next`] checking the point `offset` ahead of the one the controller is allowed to ([`TableArm::allow`]) |
//! | STOP_C (an unavailable zone ahead) | the coordinator's *sleep*: the arm halts ([`TableArm::halt`]) and brakes, short of the border |
//! | CONTINUE | the grant that follows the wake-up: the halt lifted |
//! | STOP_D (the trajectory cannot be completed) | a leg given up for another arm in the way: round it, or back |
//! | TRAJECTORY_END | [`Next::End`], told to the coordinator |

use std::collections::{BTreeSet, VecDeque};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_ports::Name;
use imrs_sim::scara::Scara;
use imrs_sim::table::{ArmSpec, GRIPPER_RADIUS, TableArm, WORK_Z};
use nalgebra::Point2;

mod avoid;

use super::layout::{RACK, SCREWDRIVER};
use super::schedule::{JobAsker, JobPort};
use super::{CellStats, lock};
use imrs_coord::coordinator::{CoordinatorPorts, Message, Refused, RobotLink};
use imrs_coord::zones::{Answer, Next, Pipeline, Pose, Sweep, ZoneDef, ZoneKind};

/// Points of a trajectory, this far apart.
const SPACING: f32 = 0.02;
/// How near a point of a leg the gripper passes a zone to need it: its own radius, and
/// half a spacing, since between two points checked it is anywhere on the line joining
/// them (a leg that clips a zone's corner between two points needs the zone).
const SWEPT: f32 = GRIPPER_RADIUS + SPACING / 2.0;
/// How near an allowed point the tool must come to have reached it.
const REACHED: f32 = 1e-4;
/// How many points ahead an arm checks its links against the others'.
const LOOKAHEAD: usize = 5;
/// How far apart two arms' links are kept.
pub(crate) const MARGIN: f32 = 0.03;
/// How often a blocked or idle arm looks again.
const RETRY: Duration = Duration::from_millis(200);
/// How long an arm waits for a stopped arm in its way before it goes round it.
const DETOUR_AFTER: Duration = Duration::from_secs(1);
/// How long before the later of two arms that block each other backs off (the earlier
/// after twice as long), home or a short way back or aside; and how long it then lets the
/// other pass.
const BACK_OFF_AFTER: Duration = Duration::from_secs(3);

/// What a request for a zone or the tool came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Got {
    Granted,
    /// Told to back off: the victim of a deadlock, it waits for nothing any more.
    BackOff,
}

/// How one straight leg of a trajectory ended.
enum Leg {
    Arrived,
    /// Blocked by a stopped arm: go round it through these points.
    Via(Vec<Point2<f32>>),
    /// Blocked for long, with no way round: back off to this point first.
    BackOff(Point2<f32>),
    /// The victim of a deadlock the coordinator found: it waits for nothing any more.
    Victim,
}

struct Driver {
    name: Name,
    index: usize,
    arm: TableArm,
    scara: Scara,
    speed: f32,
    /// How fast it speeds up and brakes, in m/s².
    acceleration: f32,
    home: Point2<f32>,
    link: RobotLink,
    zones: Arc<Vec<ZoneDef>>,
    ctx: Ctx<()>,
    stats: Arc<Mutex<CellStats>>,
    /// Which of the seed's mechanisms it uses.
    mechanisms: Mechanisms,
    /// Where it last told the coordinator it was.
    last_told: Option<Point2<f32>>,
}

/// Which of the seed's mechanisms an arm uses.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mechanisms {
    /// The pipeline's offset, if chosen rather than computed from the stopping distance.
    pub(crate) offset: Option<usize>,
    /// Whether it has the coordinator check its way ahead against the other arms, and
    /// waits, goes round or backs off.
    pub(crate) geometric: bool,
    /// Whether it goes home after every job, or straight on to the next.
    pub(crate) via_home: bool,
    /// Whether, refused at a border, it gives up its rights to move in the shared zones it
    /// is in, as the seed's robots do.
    pub(crate) gives_up_rights: bool,
}

/// STOP_C, a step of it: brakes the arm; resolves after the world's next step, to where its
/// links are then and whether it stands still.
async fn braking(arm: TableArm) -> (Option<Pose>, bool) {
    arm.halt();
    let still = arm.step().await.at_rest();
    (pose(&arm.scara(), &arm.at()), still)
}

/// The links of `scara` with its tool at `tool`, if it reaches there.
fn pose(scara: &Scara, tool: &Point2<f32>) -> Option<Pose> {
    let joints = scara.joints(tool)?;
    Some(joints.map(|joint| [joint.x, joint.y]))
}

/// The zones of `zones` that a ball of `radius` at `point`, at the working height, reaches
/// into.
fn zones_near(zones: &[ZoneDef], point: Point2<f32>, radius: f32) -> Vec<Name> {
    let point = [point.x, point.y, WORK_Z];
    zones
        .iter()
        .filter(|zone| zone.touches(point, radius))
        .map(|zone| zone.name.clone())
        .collect()
}

/// What a request came to: its answer, `None` if the robot was told to back off, or why it
/// failed.
fn answered<T>(asked: Result<T, Refused>) -> Result<Option<T>, String> {
    match asked {
        Ok(answer) => Ok(Some(answer)),
        Err(Refused::BackOff) => Ok(None),
        Err(Refused::Failed(why)) => Err(why),
    }
}

/// The arm module for `arm` (the scheduler's robot `index`, laid out as `spec`), in a
/// cell of `zones` whose arms use `mechanisms`.
pub(crate) fn arm_module(
    (arm, spec, index): (TableArm, &ArmSpec, usize),
    coordinator: &CoordinatorPorts,
    jobs: &JobPort,
    zones: Arc<Vec<ZoneDef>>,
    stats: Arc<Mutex<CellStats>>,
    mechanisms: Mechanisms,
) -> ModuleSpec<()> {
    let (spec, coordinator, jobs) = (spec.clone(), coordinator.clone(), jobs.clone());
    let module: Name = arm.name().clone();
    ModuleSpec::new(module.as_str(), ()).task(module.as_str(), move |ctx| {
        let (arm, spec) = (arm.clone(), spec.clone());
        let (coordinator, jobs) = (coordinator.clone(), jobs.clone());
        let (name, zones, stats) = (module.clone(), Arc::clone(&zones), Arc::clone(&stats));
        async move {
            let mut driver = Driver {
                link: coordinator.link(name.as_str())?,
                name: name.clone(),
                index,
                scara: spec.arm,
                speed: spec.speed,
                acceleration: spec.acceleration,
                home: spec.home,
                arm,
                zones,
                ctx,
                stats: Arc::clone(&stats),
                mechanisms,
                last_told: None,
            };
            let mut ask = jobs.user_named(name.as_str())?;
            let result = driver.work(&mut ask).await;
            if let Err(why) = &result {
                lock(&stats).failures.push(format!("{name}: {why}"));
            }
            result.map_err(Into::into)
        }
    })
}

impl Driver {
    async fn work(&mut self, ask: &mut JobAsker) -> Result<(), String> {
        let mut finished = None;
        self.tell_position().await?;
        loop {
            let here = self.arm.at();
            let job = ask
                .send((self.index, finished.take(), [here.x, here.y]))
                .await
                .map_err(|error| error.to_string())?;
            let Some(job) = job else {
                // Idle, it waits out of the way.
                self.go_surely(self.home).await?;
                self.ctx.delay(RETRY).await;
                continue;
            };
            let started = self.ctx.now();
            // Told to back off on its way, it starts the job again, the tool put back.
            while !self.reach_job(job.tool, job.at.into()).await? {}
            self.ctx.delay(job.work).await;
            if job.tool {
                self.return_tool().await?;
            }
            if self.mechanisms.via_home {
                self.go_surely(self.home).await?;
            }
            let mut stats = lock(&self.stats);
            stats.jobs[self.index] += 1;
            stats.busy[self.index] += self.ctx.now().saturating_duration_since(started);
            finished = Some((job.unit, job.task));
        }
    }

    /// To a job at `at`, with the tool if it needs it; false if it was told to back off
    /// on the way (it is home then, holding nothing it is not in).
    async fn reach_job(&mut self, tool: bool, at: Point2<f32>) -> Result<bool, String> {
        if tool {
            // Told to back off while it waits for the tool, it gets out of the zone it is
            // in and waits for nothing: it asks again once the others had time to move.
            while self.acquire(&SCREWDRIVER.into()).await? == Got::BackOff {
                lock(&self.stats).victims += 1;
                self.go_surely(self.home).await?;
                self.ctx.delay(BACK_OFF_AFTER).await;
            }
            if !self.go(RACK.into()).await? {
                self.tell(Message::Release(SCREWDRIVER.into())).await?;
                return Ok(false);
            }
            self.arm.grasp_tool().map_err(|error| error.to_string())?;
        }
        if !self.go(at).await? {
            if tool {
                self.return_tool().await?;
            }
            return Ok(false);
        }
        Ok(true)
    }

    /// Puts the tool back on its rack, and says so.
    async fn return_tool(&mut self) -> Result<(), String> {
        self.go_surely(RACK.into()).await?;
        self.arm.put_tool().map_err(|error| error.to_string())?;
        self.tell(Message::Release(SCREWDRIVER.into())).await?;
        Ok(())
    }

    /// Goes to `to`, however often it is told to back off on the way.
    async fn go_surely(&mut self, to: Point2<f32>) -> Result<(), String> {
        while !self.go(to).await? {}
        Ok(())
    }

    /// Its links with the tool at `tool`, if it reaches there.
    fn pose(&self, tool: &Point2<f32>) -> Option<Pose> {
        pose(&self.scara, tool)
    }

    /// Its links at each of `points` it reaches.
    fn sweep(&self, points: &[Point2<f32>]) -> Sweep {
        points.iter().filter_map(|point| self.pose(point)).collect()
    }

    /// Tells the coordinator where its links are, if they moved since it last told.
    async fn tell_if_moved(&mut self) -> Result<(), String> {
        if self.last_told == Some(self.arm.at()) {
            return Ok(());
        }
        self.tell_position().await
    }

    /// Tells the coordinator where its links are now (position information).
    async fn tell_position(&mut self) -> Result<(), String> {
        let here = self.arm.at();
        self.last_told = Some(here);
        let pose = self
            .pose(&here)
            .ok_or_else(|| format!("{}: its tool at {here} is out of its reach", self.name))?;
        self.link
            .at(pose)
            .await
            .map_err(|refused| format!("{refused:?}"))
    }

    /// The arms in the way of its links at `points`, where they told the coordinator
    /// they are.
    async fn blockers(&mut self, points: &[Point2<f32>]) -> Result<Vec<Name>, String> {
        let sweep = self.sweep(points);
        self.link
            .check(sweep)
            .await
            .map_err(|refused| format!("{refused:?}"))
    }

    /// The same, said while it waits for them, stopped, holding only what it is in: an
    /// arm asleep in its way that waits for what it holds is told to back off.
    async fn waiting_on(&mut self, points: &[Point2<f32>]) -> Result<Vec<Name>, String> {
        let sweep = self.sweep(points);
        self.link
            .wait_on(sweep)
            .await
            .map_err(|refused| format!("{refused:?}"))
    }

    /// The zones its gripper is in, at `point`.
    fn zones_at(&self, point: Point2<f32>) -> Vec<Name> {
        zones_near(&self.zones, point, GRIPPER_RADIUS)
    }

    fn is_shared(&self, zone: &Name) -> bool {
        self.zones
            .iter()
            .any(|z| z.name == *zone && z.kind == ZoneKind::Shared)
    }

    async fn tell(&mut self, message: Message) -> Result<Answer, String> {
        self.link
            .tell(message)
            .await
            .map_err(|refused| format!("{refused:?}"))
    }

    /// Asks for a zone or the tool until granted, stopped meanwhile (STOP_C).
    async fn acquire(&mut self, resource: &Name) -> Result<Got, String> {
        self.acquire_moving_in(resource, &[]).await
    }

    /// Asks for a zone or the tool until granted, as [`acquire`](Self::acquire) does, while
    /// it moves in the shared zones `moving_in`. Stopped at the border, it gives up its
    /// right to move in them (a position message each), and asks for them again once
    /// granted, before it moves on.
    async fn acquire_moving_in(
        &mut self,
        resource: &Name,
        moving_in: &[Name],
    ) -> Result<Got, String> {
        let asked = self.link.acquire_giving_up(resource.as_str(), moving_in);
        let Some(given_up) = answered(asked.await)? else {
            return Ok(Got::BackOff);
        };
        lock(&self.stats).rights_given_up += given_up.len() as u32;
        self.reacquire_shared(given_up).await
    }

    /// Asks again for the rights to move in the shared zones `shared`, one after the
    /// other; stopped at a border meanwhile, it gives up again those it has had back.
    async fn reacquire_shared(&mut self, shared: Vec<Name>) -> Result<Got, String> {
        let mut held: Vec<Name> = Vec::new();
        let mut pending: std::collections::VecDeque<Name> = shared.into();
        while let Some(zone) = pending.pop_front() {
            let asked = self.link.acquire_giving_up(zone.as_str(), &held);
            let Some(given_up) = answered(asked.await)? else {
                return Ok(Got::BackOff);
            };
            held.retain(|h| !given_up.contains(h));
            pending.extend(given_up);
            held.push(zone);
        }
        Ok(Got::Granted)
    }

    /// Moves the tool to `to`, going round or backing off from arms in the way. Backed
    /// off, it gives the other arm the time to pass before it goes on. Returns false if it
    /// was the victim of a deadlock: then it has gone home instead, and waited there.
    async fn go(&mut self, to: Point2<f32>) -> Result<bool, String> {
        // Each leg: where to, whether it may back off, whether it is a back-off.
        let mut legs: Vec<(Point2<f32>, bool, bool)> = vec![(to, true, false)];
        let mut arrived = true;
        while let Some((target, may_back_off, backing)) = legs.pop() {
            match self.leg(target, may_back_off).await? {
                Leg::Arrived => {
                    if backing {
                        self.ctx.delay(BACK_OFF_AFTER).await;
                    }
                }
                Leg::Via(points) => {
                    legs.push((target, may_back_off, backing));
                    legs.extend(points.into_iter().rev().map(|p| (p, false, false)));
                }
                Leg::BackOff(point) => {
                    legs.push((target, may_back_off, backing));
                    legs.push((point, false, true));
                }
                Leg::Victim => {
                    lock(&self.stats).victims += 1;
                    legs = vec![(self.home, false, true)];
                    arrived = false;
                }
            }
        }
        Ok(arrived)
    }

    /// One straight leg through the pipeline, its three stages at once: the arm's
    /// controller moves towards the points it was allowed (on the world's steps) while
    /// this task computes the next point and checks it, `offset` points ahead of the one
    /// the arm is allowed to.
    async fn leg(&mut self, to: Point2<f32>, may_back_off: bool) -> Result<Leg, String> {
        let from = self.arm.at();
        let count = ((to - from).norm() / SPACING).ceil().max(1.0) as usize;
        // The first point is where the arm stands: the pipeline learns which zones it is
        // in, asks for them, and releases them once it has left.
        let points: Vec<Point2<f32>> = (0..=count)
            .map(|i| from + (to - from) * (i as f32 / count as f32))
            .collect();
        let mut pipeline = Pipeline::new(
            self.name.clone(),
            points.iter().map(|p| [p.x, p.y, WORK_Z]),
            self.speed,
            self.acceleration,
            SPACING,
        );
        if let Some(offset) = self.mechanisms.offset {
            pipeline = pipeline.with_offset(offset);
        }
        self.arm.start_leg(to).map_err(|error| error.to_string())?;
        // The points allowed to the arm and not yet reached: how far along the leg each
        // lies, and the zones the arm has left once there.
        let mut allowed: VecDeque<(f32, Vec<Name>)> = VecDeque::new();
        let zones = Arc::clone(&self.zones);
        // The points of the leg lie at the working height.
        let zones_at = |point: [f32; 3]| zones_near(&zones, Point2::new(point[0], point[1]), SWEPT);
        // The zones each point of the leg needs, for the way ahead.
        let needs: Vec<Vec<Name>> = points
            .iter()
            .map(|p| zones_near(&zones, *p, SWEPT))
            .collect();
        let mut next = 0;
        loop {
            self.track(&mut allowed).await?;
            // Two points allowed ahead: more than the arm moves in a step of the world, so
            // that it never reaches the last before the next is allowed.
            if allowed.len() >= 2 {
                self.arm.step().await;
                continue;
            }
            match pipeline.next(zones_at) {
                Next::Request(zone) => {
                    // Every right to move in a shared zone it holds, the one it is in and
                    // those granted ahead: refused at the border, it stops, and gives them
                    // up while it waits.
                    let moving_in: Vec<Name> = pipeline
                        .holding()
                        .chain(allowed.iter().flat_map(|(_, release)| release))
                        .filter(|held| self.mechanisms.gives_up_rights && self.is_shared(held))
                        .cloned()
                        .collect::<BTreeSet<Name>>()
                        .into_iter()
                        .collect();
                    let arm = self.arm.clone();
                    let asked = self
                        .link
                        .acquire_stopping(zone.as_str(), &moving_in, || braking(arm.clone()))
                        .await;
                    let got = match answered(asked)? {
                        Some(given_up) => {
                            // Granted: its own, even if it backs off before it moves on.
                            pipeline.granted(zone.clone());
                            lock(&self.stats).rights_given_up += given_up.len() as u32;
                            self.reacquire_shared(given_up).await?
                        }
                        None => Got::BackOff,
                    };
                    if got == Got::BackOff {
                        // The victim of a deadlock: it gets out of the way, home, and
                        // comes back; the zones it is in stay its own until it has left.
                        self.halt().await?;
                        self.abandon(&pipeline, &mut allowed).await?;
                        return Ok(Leg::Victim);
                    }
                    // CONTINUE, if it was stopped: where it stands allows nothing new.
                    self.arm
                        .allow(self.arm.at())
                        .map_err(|error| error.to_string())?;
                }
                Next::Move { point, release } => {
                    if self.mechanisms.geometric {
                        let reach = (next + pipeline.offset() + LOOKAHEAD).min(points.len());
                        // Past the points the pipeline checked, the way ahead ends at the
                        // border of a zone not granted: whoever is inside is the zone's to
                        // keep, and is waited for there, asleep, as the seed's robots do.
                        let granted = |i: usize| {
                            (needs[i].iter()).all(|zone| pipeline.holding().any(|h| h == zone))
                        };
                        let reach = (next..reach).find(|&i| !granted(i)).unwrap_or(reach);
                        let ahead = &points[next..reach];
                        let taken = (&pipeline, &mut allowed);
                        if let Some(leg) = self.clear(ahead, &to, taken, may_back_off).await? {
                            // The zones it would have left at this point are its own too.
                            allowed.push_back((f32::INFINITY, release));
                            self.abandon(&pipeline, &mut allowed).await?;
                            return Ok(leg);
                        }
                    }
                    let point = Point2::new(point[0], point[1]);
                    self.arm.allow(point).map_err(|error| error.to_string())?;
                    allowed.push_back(((point - from).norm(), release));
                    next += 1;
                }
                Next::End => {
                    // Allowed to its end, the controller stops there.
                    while !self.arm.progress().arrived() {
                        self.arm.step().await;
                        self.track(&mut allowed).await?;
                    }
                    self.track(&mut allowed).await?;
                    // Stopped in a shared zone: another may move there now.
                    // (Every shared zone the pipeline asked for here, within its reach.)
                    for zone in zones_near(&self.zones, to, SWEPT) {
                        if self.is_shared(&zone) {
                            self.tell(Message::Position(zone)).await?;
                        }
                    }
                    self.tell(Message::TrajectoryEnd).await?;
                    return Ok(Leg::Arrived);
                }
            }
        }
    }

    /// Tells the coordinator what the arm did since it last told: where its links are, if
    /// it moved, and the zones it has left at each allowed point it reached.
    async fn track(&mut self, allowed: &mut VecDeque<(f32, Vec<Name>)>) -> Result<(), String> {
        self.tell_if_moved().await?;
        let along = self.arm.progress().along;
        while allowed
            .front()
            .is_some_and(|(point, _)| along >= point - REACHED)
        {
            let Some((_, release)) = allowed.pop_front() else {
                break;
            };
            for zone in release {
                self.tell(Message::Release(zone)).await?;
            }
        }
        Ok(())
    }

    /// STOP_C for an arm in the way: brakes, telling where it is as it goes.
    async fn halt(&mut self) -> Result<(), String> {
        self.arm.halt();
        while !self.arm.progress().at_rest() {
            self.arm.step().await;
            self.tell_if_moved().await?;
        }
        Ok(())
    }

    /// On a leg given up: releases the zones it was to leave at an allowed point ahead but
    /// is not in (it braked out of them): no point it will go to on this leg needs them.
    async fn release_left(
        &mut self,
        allowed: &mut VecDeque<(f32, Vec<Name>)>,
    ) -> Result<(), String> {
        let inside = self.zones_at(self.arm.at());
        let mut left = Vec::new();
        for (_, release) in allowed.iter_mut() {
            release.retain(|zone| {
                let gone = !inside.contains(zone);
                if gone && !left.contains(zone) {
                    left.push(zone.clone());
                }
                !gone
            });
        }
        for zone in left {
            self.tell(Message::Release(zone)).await?;
        }
        Ok(())
    }

    /// Gives up a leg part-way: frees what it holds but is not inside.
    async fn abandon(
        &mut self,
        pipeline: &Pipeline,
        allowed: &mut VecDeque<(f32, Vec<Name>)>,
    ) -> Result<(), String> {
        self.track(allowed).await?;
        self.release_left(allowed).await?;
        let inside = self.zones_at(self.arm.at());
        for zone in pipeline.holding().cloned().collect::<Vec<_>>() {
            if !inside.contains(&zone) {
                self.tell(Message::Release(zone)).await?;
            }
        }
        self.tell(Message::TrajectoryEnd).await?;
        Ok(())
    }
}
