//! An arm of the table cell as a module: it asks the scheduler for work, and carries each
//! job out through the coordinator — its trajectory's points checked ahead in the
//! pipeline (zones requested before the arm reaches them, released once it has left them),
//! and its links checked against the other arms' before every step.
//!
//! The seed's messages between an arm's two controllers, here:
//!
//! | seed | here |
//! |---|---|
//! | TRAJECTORY | a straight leg, its points spaced 2 cm |
//! | TRAJECTORY_POINT (check a point) | [`Pipeline::next`] checking the point `offset` ahead |
//! | STOP_C (an unavailable zone ahead) | the coordinator's *sleep*: the arm waits, short of the border |
//! | CONTINUE | the grant that follows the wake-up |
//! | STOP_D (the trajectory cannot be completed) | a leg given up for another arm in the way: round it, or back |
//! | TRAJECTORY_END | [`Next::End`], told to the coordinator |

use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_ports::Name;
use imrs_sim::scara::Scara;
use imrs_sim::table::{GRIPPER_RADIUS, Table, TableArm, WORK_Z};
use nalgebra::Point2;

use super::clearance::{blockers, obstacles};
use super::layout::{RACK, SCREWDRIVER};
use super::schedule::{JobAsker, JobPort};
use super::{CellStats, lock};
use imrs_coord::coordinator::{CoordinatorPorts, Message, Refused, RobotLink};
use imrs_coord::zones::{Answer, Next, Pipeline, ZoneDef, ZoneKind, detour};

/// Points of a trajectory, this far apart.
const SPACING: f32 = 0.02;
/// The arms' deceleration: with their speeds, a stopping distance of 2 to 9 cm.
const DECELERATION: f32 = 2.5;
/// How many points ahead an arm checks its links against the others'.
const LOOKAHEAD: usize = 5;
/// How far apart two arms' links are kept.
const MARGIN: f32 = 0.03;
/// How often a blocked or idle arm looks again.
const RETRY: Duration = Duration::from_millis(200);
/// How long an arm waits for a stopped arm in its way before it goes round it.
const DETOUR_AFTER: Duration = Duration::from_secs(1);
/// How long before the later of two arms that block each other backs off, home; and how
/// long it then lets the other pass.
const BACK_OFF_AFTER: Duration = Duration::from_secs(3);

/// How one straight leg of a trajectory ended.
enum Leg {
    Arrived,
    /// Blocked by a stopped arm: go round it through these points.
    Via(Vec<Point2<f32>>),
    /// Blocked by an arm that is itself blocked: back off to this point first.
    BackOff(Point2<f32>),
}

struct Driver {
    name: Name,
    index: usize,
    arm: TableArm,
    scara: Scara,
    speed: f32,
    table: Table,
    link: RobotLink,
    zones: Arc<Vec<ZoneDef>>,
    ctx: Ctx<()>,
    stats: Arc<Mutex<CellStats>>,
    /// Whether it has just backed off, and lets the other pass before going on.
    yield_after_back_off: bool,
}

/// The arm module for `name` (the scheduler's robot `index`).
pub(crate) fn arm_module(
    name: &str,
    index: usize,
    table: &Table,
    coordinator: &CoordinatorPorts,
    jobs: &JobPort,
    zones: Arc<Vec<ZoneDef>>,
    stats: Arc<Mutex<CellStats>>,
) -> ModuleSpec<()> {
    let (table, coordinator, jobs) = (table.clone(), coordinator.clone(), jobs.clone());
    let module: Name = name.into();
    ModuleSpec::new(name, ()).task(name, move |ctx| {
        let (table, coordinator, jobs) = (table.clone(), coordinator.clone(), jobs.clone());
        let (name, zones, stats) = (module.clone(), Arc::clone(&zones), Arc::clone(&stats));
        async move {
            let arm = table.arm(name.as_str())?;
            let spec = table.layout().arms[index].clone();
            let mut driver = Driver {
                link: coordinator.link(name.as_str())?,
                name: name.clone(),
                index,
                scara: spec.arm,
                speed: spec.speed,
                arm,
                table,
                zones,
                ctx,
                stats: Arc::clone(&stats),
                yield_after_back_off: false,
            };
            let mut ask = jobs.user_named(name.as_str())?;
            let result = driver.work(&mut ask, spec.home).await;
            if let Err(why) = &result {
                lock(&stats).failures.push(format!("{name}: {why}"));
            }
            result.map_err(Into::into)
        }
    })
}

impl Driver {
    async fn work(&mut self, ask: &mut JobAsker, home: Point2<f32>) -> Result<(), String> {
        let mut finished = None;
        loop {
            let job = ask
                .send((self.index, finished.take()))
                .await
                .map_err(|error| error.to_string())?;
            let Some(job) = job else {
                self.ctx.delay(RETRY).await;
                continue;
            };
            let started = self.ctx.now();
            if job.tool {
                self.acquire(&SCREWDRIVER.into()).await?;
                self.go(RACK.into()).await?;
                self.arm.grasp_tool().map_err(|error| error.to_string())?;
            }
            self.go(job.at.into()).await?;
            self.ctx.delay(job.work).await;
            if job.tool {
                self.go(RACK.into()).await?;
                self.arm.put_tool().map_err(|error| error.to_string())?;
                self.tell(Message::Release(SCREWDRIVER.into())).await?;
            }
            self.go(home).await?;
            let mut stats = lock(&self.stats);
            stats.jobs[self.index] += 1;
            stats.busy[self.index] += self.ctx.now().saturating_duration_since(started);
            finished = Some((job.unit, job.task));
        }
    }

    fn zones_at(&self, point: Point2<f32>) -> Vec<Name> {
        let point = [point.x, point.y, WORK_Z];
        self.zones
            .iter()
            .filter(|zone| zone.touches(point, GRIPPER_RADIUS))
            .map(|zone| zone.name.clone())
            .collect()
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
    async fn acquire(&mut self, resource: &Name) -> Result<(), String> {
        match self.link.acquire(resource.as_str()).await {
            Ok(()) => Ok(()),
            // Every arm takes the tool before any zone and frees the zones it holds
            // before it waits on another arm, so no cycle of waits can form here; a
            // back-off would mean the coordinator found one, and is reported as such.
            Err(Refused::BackOff) => Err(format!(
                "told to back off while asking for {resource}: a deadlock the cell's \
                 order of requests should have made impossible"
            )),
            Err(Refused::Failed(why)) => Err(why),
        }
    }

    /// Moves the tool to `to`, going round or backing off from arms in the way.
    async fn go(&mut self, to: Point2<f32>) -> Result<(), String> {
        let mut legs: Vec<(Point2<f32>, bool)> = vec![(to, true)];
        while let Some((target, may_back_off)) = legs.pop() {
            if may_back_off && std::mem::take(&mut self.yield_after_back_off) {
                self.ctx.delay(BACK_OFF_AFTER).await;
            }
            match self.leg(target, may_back_off).await? {
                Leg::Arrived => {}
                Leg::Via(points) => {
                    legs.push((target, may_back_off));
                    legs.extend(points.into_iter().rev().map(|p| (p, false)));
                }
                Leg::BackOff(point) => {
                    legs.push((target, may_back_off));
                    legs.push((point, false));
                    // Backed off: give the other arm the time to pass before going on.
                    self.yield_after_back_off = true;
                }
            }
        }
        Ok(())
    }

    /// One straight leg through the pipeline.
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
            DECELERATION,
            SPACING,
        );
        let mut at = 0;
        loop {
            let zones = Arc::clone(&self.zones);
            let zones_at = |point: [f32; 3]| -> Vec<Name> {
                zones
                    .iter()
                    .filter(|zone| zone.touches(point, GRIPPER_RADIUS))
                    .map(|zone| zone.name.clone())
                    .collect()
            };
            match pipeline.next(zones_at) {
                Next::Request(zone) => {
                    self.acquire(&zone).await?;
                    pipeline.granted(zone);
                }
                Next::Move { point, release } => {
                    let ahead = &points[at..(at + LOOKAHEAD).min(points.len())];
                    if let Some(leg) = self.clear(ahead, &to, &pipeline, may_back_off).await? {
                        self.abandon(&pipeline).await?;
                        return Ok(leg);
                    }
                    self.arm
                        .move_to(Point2::new(point[0], point[1]))
                        .await
                        .map_err(|error| error.to_string())?;
                    // Only now, at the point, has the gripper left these zones.
                    for zone in release {
                        self.tell(Message::Release(zone)).await?;
                    }
                    at += 1;
                }
                Next::End => {
                    // Stopped in a shared zone: another may move there now.
                    for zone in self.zones_at(to) {
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

    /// Waits until the arm's links at `ahead` keep clear of every other arm, freeing
    /// meanwhile what it holds but is not inside (and its right to move in a shared zone
    /// it is in), so that whoever is in its way can move; asks for them again before it
    /// goes on. Or gives up the leg: round the arms in the way, or back.
    async fn clear(
        &mut self,
        ahead: &[Point2<f32>],
        leg_end: &Point2<f32>,
        pipeline: &Pipeline,
        may_back_off: bool,
    ) -> Result<Option<Leg>, String> {
        let mut freed: Vec<Name> = Vec::new();
        let mut waited = Duration::ZERO;
        loop {
            let others = self.table.joints();
            let blocking = blockers(&self.name, &self.scara, ahead, &others, MARGIN);
            if blocking.is_empty() {
                if freed.is_empty() {
                    return Ok(None);
                }
                for zone in std::mem::take(&mut freed) {
                    self.acquire(&zone).await?;
                }
                // The others may have moved while this arm waited for its zones.
                continue;
            }
            if waited.is_zero() {
                lock(&self.stats).geometric_blocks += 1;
            }
            // Whatever it holds and is not inside, and its right to move where it is in a
            // shared zone, it frees while it waits — every time it finds itself blocked,
            // also after it asked for them again — so that no arm waits on it for a zone
            // while it waits on that arm for space.
            let inside = self.zones_at(self.arm.at());
            for zone in pipeline.holding().cloned().collect::<Vec<_>>() {
                if freed.contains(&zone) {
                    continue;
                }
                if !inside.contains(&zone) {
                    self.tell(Message::Release(zone.clone())).await?;
                    freed.push(zone);
                } else if self.is_shared(&zone) {
                    self.tell(Message::Position(zone.clone())).await?;
                    freed.push(zone);
                }
            }
            if waited >= DETOUR_AFTER
                && let Some(points) = self.round(&blocking, &others, leg_end)
            {
                lock(&self.stats).detours += 1;
                return Ok(Some(Leg::Via(points)));
            }
            // Two arms in each other's way: the later-named backs off; if it cannot, the
            // other does, after twice as long.
            let my_turn =
                blocking.iter().all(|other| *other < self.name) || waited >= 2 * BACK_OFF_AFTER;
            if waited >= BACK_OFF_AFTER
                && may_back_off
                && my_turn
                && let Some(point) = self.back_point(&others)
            {
                lock(&self.stats).back_offs += 1;
                return Ok(Some(Leg::BackOff(point)));
            }
            self.ctx.delay(RETRY).await;
            waited += RETRY;
        }
    }

    /// An alternative trajectory round the arms in the way, from here to the leg's end,
    /// whose every point keeps this arm's links clear of every other arm.
    fn round(
        &self,
        blocking: &[Name],
        others: &[(Name, [Point2<f32>; 3])],
        leg_end: &Point2<f32>,
    ) -> Option<Vec<Point2<f32>>> {
        let here = self.arm.at();
        let end = *leg_end;
        let path = [[here.x, here.y, 0.0], [end.x, end.y, 0.0]];
        let radius = imrs_sim::table::LINK_RADIUS;
        let around = detour(&path, radius, &obstacles(blocking, others), MARGIN, 0.25)?;
        let points: Vec<Point2<f32>> = around.iter().map(|p| Point2::new(p[0], p[1])).collect();
        // Check the whole way, every spacing, links and all.
        let sampled: Vec<Point2<f32>> = points
            .windows(2)
            .flat_map(|pair| {
                let n = ((pair[1] - pair[0]).norm() / SPACING).ceil().max(1.0) as usize;
                (0..=n).map(move |i| pair[0] + (pair[1] - pair[0]) * (i as f32 / n as f32))
            })
            .collect();
        let reachable = sampled.iter().all(|p| self.scara.reaches(p));
        (reachable && blockers(&self.name, &self.scara, &sampled, others, MARGIN).is_empty())
            .then(|| points[1..].to_vec())
    }

    /// Where to back off to: home, if the first steps there are clear.
    fn back_point(&self, others: &[(Name, [Point2<f32>; 3])]) -> Option<Point2<f32>> {
        let here = self.arm.at();
        let home = self.table.layout().arms[self.index].home;
        let towards = home - here;
        if towards.norm() < SPACING {
            return None;
        }
        let step = towards.normalize() * SPACING;
        let first: Vec<Point2<f32>> = (1..=LOOKAHEAD).map(|i| here + step * i as f32).collect();
        blockers(&self.name, &self.scara, &first, others, MARGIN)
            .is_empty()
            .then_some(home)
    }

    /// Gives up a leg part-way: frees what it holds but is not inside.
    async fn abandon(&mut self, pipeline: &Pipeline) -> Result<(), String> {
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
