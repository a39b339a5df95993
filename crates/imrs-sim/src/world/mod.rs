//! The simulated cell's state: arms, conveyors, pallets, feeders and the rapier world that
//! measures them.

pub(crate) mod arm;
mod conveyor;
mod physics;

use std::collections::BTreeSet;
use std::time::Duration;

use imrs_ports::Instant;

use self::arm::{Arm, distance};
use self::conveyor::{Conveyor, PalletState};
use self::physics::Physics;
use crate::error::DeviceError;
use crate::event::{SimEvent, SimEventKind};
use crate::fault::{Fault, FaultKind};
use crate::ids::{FeederId, Line, PalletId, RobotId, Role, Station};
use crate::layout::{
    CARD_SIZE, CHIP_X, FEEDER_X, LOAD_X, PALLET_HALF, REACH_TOLERANCE, REFILL_CHIPS, REFILL_DELAY,
    ZONE_CENTRE, line_y,
};
use crate::rng::Rng;
use crate::scara::Elbow;
use crate::scene::{ArmPose, BoxPose, FeederView, PalletPose, Scene};

pub(crate) use self::conveyor::Pallet;

/// Where a robot's tool should go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// Its resting position, clear of the conveyor and the zone.
    Home,
    /// Above a feeder of the shared zone.
    Feeder(FeederId),
    /// Above the centre of the card on the pallet its station holds.
    Card,
    /// Above a place on that card: metres from the card's corner nearest the gate and line
    /// A, along the conveyor and across it (see [`CARD_SIZE`](crate::layout::CARD_SIZE)).
    OnCard([f32; 2]),
    /// Above the magazine of blank cards (for the card-loading robot).
    Magazine,
    /// Any point of the working plane, in metres.
    Point([f32; 2]),
}

pub(crate) struct Feeder {
    pub(crate) id: FeederId,
    pub(crate) chip: u32,
    pub(crate) stock: u32,
    at: [f32; 2],
    /// When the operator, who saw it empty, will have refilled it.
    refill_at: Option<Instant>,
}

/// The chip numbers of the feeders, as in the Appendix's work schedule (GRASP(1), GRASP(4),
/// ..., GRASP(12)).
pub const FEEDER_CHIPS: [u32; 4] = [1, 4, 7, 12];

pub(crate) struct World {
    physics: Physics,
    arms: Vec<Arm>,
    lines: [Conveyor; 2],
    pub(crate) feeders: Vec<Feeder>,
    /// Pending faults, soonest first.
    faults: Vec<Fault>,
    in_zone: Vec<bool>,
    /// The closest two arms came while both were in the feeder zone, in metres.
    pub(crate) closest_in_zone: Option<f32>,
    touching: BTreeSet<(usize, usize)>,
    last_step: Option<Instant>,
    next_pallet: u32,
    pending: Vec<SimEvent>,
    rng: Rng,
    times: Vec<RobotTimes>,
}

/// How a robot spent its time, as the simulation measured it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RobotTimes {
    /// Moving its tool.
    pub moving: Duration,
    /// Working at a place: grasping, inserting, picking, placing, screwing.
    pub working: Duration,
}

/// Where each robot stands: its base, its resting tool position, its elbow side, and (for the
/// card-loading robot) the magazine of blank cards.
fn layout(robot: RobotId) -> ([f32; 2], [f32; 2], Elbow) {
    let y = line_y(robot.line.index());
    // Load and screw robots stand outside their line; chip robots between the lines.
    let outside = match robot.line {
        Line::A => -1.0,
        Line::B => 1.0,
    };
    match robot.role {
        // The two robots of a load station bend their elbows away from each other.
        Role::LoadCard => (
            [LOAD_X - 0.35, y + outside * 0.45],
            [LOAD_X - 0.35, y + outside * 0.1],
            if outside < 0.0 {
                Elbow::Left
            } else {
                Elbow::Right
            },
        ),
        Role::ScrewInCard => (
            [LOAD_X + 0.35, y + outside * 0.45],
            [LOAD_X + 0.35, y + outside * 0.1],
            if outside < 0.0 {
                Elbow::Right
            } else {
                Elbow::Left
            },
        ),
        // Each chip robot bends its elbow away from the other line.
        Role::ChipIt => (
            [CHIP_X - 0.35, y - outside * 0.25],
            [CHIP_X - 0.1, y - outside * 0.1],
            if outside < 0.0 {
                Elbow::Right
            } else {
                Elbow::Left
            },
        ),
    }
}

fn magazine(line: Line) -> [f32; 2] {
    let outside = if line == Line::A { -1.0 } else { 1.0 };
    [LOAD_X - 0.65, line_y(line.index()) + outside * 0.15]
}

impl World {
    pub(crate) fn new(seed: u64, stocks: Option<[u32; 4]>) -> Self {
        let mut physics = Physics::new();
        let arms = RobotId::ALL
            .iter()
            .map(|&id| {
                let (base, home, side) = layout(id);
                Arm::new(id, base, home, side, &mut physics)
            })
            .collect();
        let mut rng = Rng::new(seed);
        let feeders = FEEDER_CHIPS
            .iter()
            .enumerate()
            .map(|(index, &chip)| Feeder {
                id: FeederId(index as u8),
                chip,
                stock: stocks.map_or_else(
                    || rng.range(REFILL_CHIPS.0, REFILL_CHIPS.1),
                    |stocks| stocks[index],
                ),
                at: [FEEDER_X[index], ZONE_CENTRE[1]],
                refill_at: None,
            })
            .collect();
        let mut world = Self {
            physics,
            arms,
            lines: [Conveyor::new(Line::A), Conveyor::new(Line::B)],
            feeders,
            faults: Vec::new(),
            in_zone: vec![false; RobotId::ALL.len()],
            closest_in_zone: None,
            touching: BTreeSet::new(),
            last_step: None,
            next_pallet: 0,
            pending: Vec::new(),
            rng,
            times: vec![RobotTimes::default(); RobotId::ALL.len()],
        };
        world.physics.detect();
        world
    }

    /// Whether anything moves, so that the world needs stepping.
    pub(crate) fn is_active(&self) -> bool {
        self.arms.iter().any(Arm::is_moving) || self.lines.iter().any(Conveyor::is_moving)
    }

    /// Advances the world to `now`: pallets, arms, collision detection, and what it measured.
    pub(crate) fn step(&mut self, now: Instant) -> Vec<SimEvent> {
        self.apply_due_faults(now);
        self.refill_due(now);
        let seconds = self.last_step.map_or(0.0, |last| {
            now.saturating_duration_since(last).as_secs_f32()
        });
        self.last_step = Some(now);
        let mut events = std::mem::take(&mut self.pending);
        for line in &mut self.lines {
            line.advance(seconds, now, &mut self.physics, &mut events);
        }
        for arm in &mut self.arms {
            arm.update(now, &mut self.physics);
        }
        // Only arm links take part in collisions and in the zone: while no arm moved, rapier
        // would find exactly what it found last step, so the step is skipped (pallets placed
        // meanwhile are in the world all the same; they collide with nothing).
        if self.arms.iter().any(|arm| arm.moved) {
            self.physics.detect();
        }
        self.measure(now, &mut events);
        events
    }

    /// Zone occupancy and contacts between robots, from rapier.
    fn measure(&mut self, now: Instant, events: &mut Vec<SimEvent>) {
        for (index, arm) in self.arms.iter().enumerate() {
            if !arm.moved {
                continue;
            }
            let inside = arm.colliders.iter().any(|&c| self.physics.in_zone(c));
            if inside != self.in_zone[index] {
                self.in_zone[index] = inside;
                let robot = arm.id;
                let kind = if inside {
                    SimEventKind::ZoneEntered { robot }
                } else {
                    SimEventKind::ZoneLeft { robot }
                };
                events.push(SimEvent { at: now, kind });
            }
        }
        for a in 0..self.arms.len() {
            for b in a + 1..self.arms.len() {
                if !self.arms[a].moved && !self.arms[b].moved {
                    continue;
                }
                if self.in_zone[a] && self.in_zone[b] {
                    let apart = self.arms[a]
                        .colliders
                        .iter()
                        .flat_map(|&ca| {
                            let physics = &self.physics;
                            self.arms[b]
                                .colliders
                                .iter()
                                .map(move |&cb| physics.distance(ca, cb))
                        })
                        .fold(f32::INFINITY, f32::min);
                    self.closest_in_zone =
                        Some(self.closest_in_zone.map_or(apart, |c| c.min(apart)));
                }
                let contact = self.arms[a].colliders.iter().find_map(|&ca| {
                    self.arms[b]
                        .colliders
                        .iter()
                        .find_map(|&cb| self.physics.touching(ca, cb))
                });
                let was = self.touching.contains(&(a, b));
                match contact {
                    Some(point) if !was => {
                        self.touching.insert((a, b));
                        events.push(SimEvent {
                            at: now,
                            kind: SimEventKind::Collision {
                                a: self.arms[a].id,
                                b: self.arms[b].id,
                                point,
                            },
                        });
                    }
                    None if was => {
                        self.touching.remove(&(a, b));
                    }
                    _ => {}
                }
            }
        }
        for arm in &mut self.arms {
            arm.moved = false;
        }
    }

    /// The feeder `feeder`, once the operator's refills due by `now` are done.
    pub(crate) fn feeder(&mut self, feeder: FeederId, now: Instant) -> Option<&mut Feeder> {
        self.refill_due(now);
        self.feeders.iter_mut().find(|f| f.id == feeder)
    }

    /// Calls the operator to a feeder found empty; it will be refilled after a while.
    pub(crate) fn report_empty(&mut self, feeder: FeederId, now: Instant) {
        if let Some(feeder) = self.feeders.iter_mut().find(|f| f.id == feeder)
            && feeder.refill_at.is_none()
        {
            feeder.refill_at = Some(now + REFILL_DELAY);
            self.pending.push(SimEvent {
                at: now,
                kind: SimEventKind::FeederEmptied { feeder: feeder.id },
            });
        }
    }

    /// Adds time a robot spent moving or working.
    pub(crate) fn spend(&mut self, robot: RobotId, spent: Duration, moving: bool) {
        let times = &mut self.times[robot.index()];
        if moving {
            times.moving += spent;
        } else {
            times.working += spent;
        }
    }

    /// How each robot spent its time so far.
    pub(crate) fn robot_times(&self) -> Vec<(RobotId, RobotTimes)> {
        RobotId::ALL
            .iter()
            .map(|&robot| (robot, self.times[robot.index()]))
            .collect()
    }

    fn refill_due(&mut self, now: Instant) {
        for feeder in &mut self.feeders {
            if feeder.refill_at.is_some_and(|at| at <= now) {
                feeder.refill_at = None;
                feeder.stock = self.rng.range(REFILL_CHIPS.0, REFILL_CHIPS.1);
                self.pending.push(SimEvent {
                    at: now,
                    kind: SimEventKind::FeederRefilled {
                        feeder: feeder.id,
                        chips: feeder.stock,
                    },
                });
            }
        }
    }

    pub(crate) fn inject(&mut self, fault: Fault) {
        let position = self
            .faults
            .partition_point(|pending| pending.at <= fault.at);
        self.faults.insert(position, fault);
    }

    /// Applies the faults that act on their own when their time comes: empty feeders, jams.
    fn apply_due_faults(&mut self, now: Instant) {
        let mut index = 0;
        while index < self.faults.len() && self.faults[index].at <= now {
            let fault = self.faults[index];
            let applied = match fault.kind {
                FaultKind::FeederEmpty(feeder) => {
                    if let Some(feeder) = self.feeders.iter_mut().find(|f| f.id == feeder) {
                        feeder.stock = 0;
                    }
                    true
                }
                FaultKind::Jam(line, station) => {
                    self.jam(line, station, now);
                    true
                }
                // A robot fault waits for the operation it breaks.
                FaultKind::Robot(_) => false,
            };
            if applied {
                self.faults.remove(index);
                self.pending.push(SimEvent {
                    at: now,
                    kind: SimEventKind::FaultStruck { fault: fault.kind },
                });
            } else {
                index += 1;
            }
        }
    }

    fn jam(&mut self, line: Line, station: Station, now: Instant) {
        let conveyor = &mut self.lines[line.index()];
        match conveyor.at_station(station) {
            Some(pallet) if pallet.state == PalletState::Held(station) => {
                pallet.state = PalletState::Jammed(station);
                let pallet = pallet.id;
                self.pending.push(SimEvent {
                    at: now,
                    kind: SimEventKind::PalletJammed {
                        line,
                        station,
                        pallet,
                    },
                });
            }
            _ => conveyor.jam_next[station.index()] = true,
        }
    }

    /// Takes the robot fault that strikes `robot` by `until`, if any: when it strikes.
    pub(crate) fn take_robot_fault(&mut self, robot: RobotId, until: Instant) -> Option<Instant> {
        let index = self
            .faults
            .iter()
            .position(|fault| fault.at <= until && fault.kind == FaultKind::Robot(robot))?;
        let fault = self.faults.remove(index);
        self.pending.push(SimEvent {
            at: fault.at,
            kind: SimEventKind::FaultStruck { fault: fault.kind },
        });
        Some(fault.at)
    }

    pub(crate) fn take_pending(&mut self) -> Vec<SimEvent> {
        std::mem::take(&mut self.pending)
    }

    pub(crate) fn arm(&mut self, robot: RobotId) -> &mut Arm {
        &mut self.arms[robot.index()]
    }

    pub(crate) fn arm_and_physics(&mut self, robot: RobotId) -> (&mut Arm, &mut Physics) {
        (&mut self.arms[robot.index()], &mut self.physics)
    }

    /// The point a robot's target names: an unknown feeder, or a point that is no point, is
    /// an error.
    pub(crate) fn point_of(&self, robot: RobotId, target: Target) -> Result<[f32; 2], DeviceError> {
        match target {
            Target::Home => Ok(self.arms[robot.index()].home),
            Target::Feeder(feeder) => self
                .feeders
                .iter()
                .find(|f| f.id == feeder)
                .map(|f| f.at)
                .ok_or(DeviceError::UnknownFeeder { feeder }),
            Target::Card => Ok(Self::card_centre(robot)),
            Target::OnCard(place) => {
                let on_card = place
                    .iter()
                    .zip(CARD_SIZE)
                    .all(|(&at, size)| (0.0..=size).contains(&at));
                if !on_card {
                    return Err(DeviceError::OffCard {
                        robot,
                        at: place.map(|metres| (metres * 1000.0).round() as i32),
                    });
                }
                let centre = Self::card_centre(robot);
                Ok([
                    centre[0] - CARD_SIZE[0] / 2.0 + place[0],
                    centre[1] - CARD_SIZE[1] / 2.0 + place[1],
                ])
            }
            Target::Magazine => Ok(magazine(robot.line)),
            Target::Point(point) if point.iter().all(|c| c.is_finite()) => Ok(point),
            Target::Point(_) => Err(DeviceError::OutOfReach {
                robot,
                target: [i32::MAX, i32::MAX],
            }),
        }
    }

    /// Where the card at `robot`'s station lies when its pallet is held: centred on it.
    fn card_centre(robot: RobotId) -> [f32; 2] {
        let y = line_y(robot.line.index());
        match robot.role {
            Role::LoadCard | Role::ScrewInCard => [LOAD_X, y],
            Role::ChipIt => [CHIP_X, y],
        }
    }

    /// Where `robot`'s tool is on the card of the pallet its station holds, in metres from
    /// the card's corner, measured against the pallet's pose in rapier; `None` unless the
    /// tool is over the card.
    pub(crate) fn tool_on_card(&mut self, robot: RobotId, now: Instant) -> Option<[f32; 2]> {
        let tool = self.arms[robot.index()].tool_at(now);
        let station = Self::station_of(robot);
        let pallet = self.lines[robot.line.index()].at_station(station)?.body();
        let centre = self.physics.position_of(pallet);
        let place = [
            tool[0] - (centre[0] - CARD_SIZE[0] / 2.0),
            tool[1] - (centre[1] - CARD_SIZE[1] / 2.0),
        ];
        let over = place
            .iter()
            .zip(CARD_SIZE)
            .all(|(&at, size)| (-REACH_TOLERANCE..=size + REACH_TOLERANCE).contains(&at));
        over.then_some(place)
    }

    /// Whether `robot`'s tool is (now) at `target`.
    pub(crate) fn is_at(&self, robot: RobotId, target: Target, now: Instant) -> bool {
        let arm = &self.arms[robot.index()];
        self.point_of(robot, target)
            .is_ok_and(|point| distance(arm.tool_at(now), point) <= REACH_TOLERANCE)
    }

    pub(crate) fn station_of(robot: RobotId) -> Station {
        match robot.role {
            Role::LoadCard | Role::ScrewInCard => Station::Load,
            Role::ChipIt => Station::Chip,
        }
    }

    /// The pallet held at `station` of `line`, ready to work on.
    pub(crate) fn held_pallet(
        &mut self,
        line: Line,
        station: Station,
    ) -> Result<&mut Pallet, DeviceError> {
        match self.lines[line.index()].at_station(station) {
            Some(pallet) if pallet.state == PalletState::Held(station) => Ok(pallet),
            Some(_) => Err(DeviceError::Jam { line, station }),
            None => Err(DeviceError::NoPallet { line, station }),
        }
    }

    /// What the pallet at a station is: held, jammed, or none.
    pub(crate) fn station_state(
        &mut self,
        line: Line,
        station: Station,
    ) -> Option<(PalletId, bool)> {
        let pallet = self.lines[line.index()].at_station(station)?;
        Some((pallet.id, matches!(pallet.state, PalletState::Jammed(_))))
    }

    pub(crate) fn conveyor(&mut self, line: Line) -> &mut Conveyor {
        &mut self.lines[line.index()]
    }

    pub(crate) fn release_pallet(&mut self, line: Line) -> PalletId {
        let id = PalletId(self.next_pallet);
        self.next_pallet += 1;
        self.lines[line.index()].release(id, &mut self.physics);
        id
    }

    pub(crate) fn scrap(&mut self, line: Line, station: Station) -> Option<PalletId> {
        self.lines[line.index()].scrap(station, &mut self.physics)
    }

    /// Takes off `line` every pallet its stations hold.
    pub(crate) fn scrap_held(&mut self, line: Line) -> Vec<PalletId> {
        self.lines[line.index()].scrap_held(&mut self.physics)
    }

    /// The cell as rapier has it now.
    pub(crate) fn scene(&self, at: Instant) -> Scene {
        let arms = self
            .arms
            .iter()
            .zip(&self.in_zone)
            .map(|(arm, &in_zone)| ArmPose {
                robot: arm.id,
                links: arm.colliders.map(|link| self.physics.link_pose(link)),
                in_zone,
            })
            .collect();
        let pallets = Line::ALL
            .iter()
            .flat_map(|&line| {
                self.lines[line.index()]
                    .pallets()
                    .map(move |pallet| (line, pallet))
            })
            .map(|(line, pallet)| PalletPose {
                line,
                pallet: pallet.id,
                pose: BoxPose {
                    centre: self.physics.position_of(pallet.body()),
                    half: PALLET_HALF,
                },
                card: pallet.card,
                chips: pallet.chips,
            })
            .collect();
        let feeders = self
            .feeders
            .iter()
            .map(|feeder| FeederView {
                id: feeder.id,
                chip: feeder.chip,
                stock: feeder.stock,
                at: [feeder.at[0], feeder.at[1], 0.0],
            })
            .collect();
        Scene {
            at,
            arms,
            pallets,
            feeders,
            zone: self.physics.zone_box(),
        }
    }

    pub(crate) fn pallet_positions(&self) -> Vec<(Line, PalletId, [f32; 3])> {
        Line::ALL
            .iter()
            .flat_map(|&line| {
                self.lines[line.index()]
                    .positions(&self.physics)
                    .into_iter()
                    .map(move |(id, at)| (line, id, at))
            })
            .collect()
    }

    /// The point of `target`, if `robot` can reach it.
    pub(crate) fn reachable(
        &self,
        robot: RobotId,
        target: Target,
    ) -> Result<[f32; 2], DeviceError> {
        let point = self.point_of(robot, target)?;
        if self.arms[robot.index()].reaches(point) {
            Ok(point)
        } else {
            Err(DeviceError::OutOfReach {
                robot,
                target: point.map(|metres| (metres * 1000.0).round() as i32),
            })
        }
    }
}
