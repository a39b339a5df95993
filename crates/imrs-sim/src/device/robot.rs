//! A robot: moves, grasps, inserts, places and screws, each taking its time on the clock.

use std::time::Duration;

use crate::error::DeviceError;
use crate::event::{SimEvent, SimEventKind};
use crate::ids::{FeederId, RobotId, Station};
use crate::layout::{GRASP_TIME, INSERT_TIME, PICK_CARD_TIME, PLACE_CARD_TIME, SCREW_TIME};
use crate::sim::Sim;
use crate::world::arm::Held;
use crate::world::{Target, World};

/// One robot of the cell.
#[derive(Debug, Clone)]
pub struct Robot {
    sim: Sim,
    id: RobotId,
}

// The simulation hands out its robots here, beside what a robot is: a robot holds the
// simulation, so the simulation's own file names no device.
impl Sim {
    /// The robot `id`.
    pub fn robot(&self, id: RobotId) -> Robot {
        Robot::new(self.clone(), id)
    }
}

impl Robot {
    fn new(sim: Sim, id: RobotId) -> Self {
        Self { sim, id }
    }

    /// Which robot this is.
    pub fn id(&self) -> RobotId {
        self.id
    }

    /// The time now, on the simulation's clock.
    pub fn now(&self) -> imrs_ports::Instant {
        self.sim.now()
    }

    /// The space the arm's links sweep moving in a straight line from `from` (or from
    /// where its tool is now) to `to`: `samples + 1` poses, each its base, elbow and tool in
    /// the working plane, computed from the same kinematics the simulation moves it by.
    pub fn sweep(
        &self,
        from: Option<Target>,
        to: Target,
        samples: usize,
    ) -> Result<Vec<[[f32; 2]; 3]>, DeviceError> {
        let robot = self.id;
        self.sim.with(|world, now| {
            let start = match from {
                Some(from) => world.reachable(robot, from)?,
                None => world.arm(robot).tool_at(now),
            };
            let end = world.reachable(robot, to)?;
            let arm = world.arm(robot);
            let samples = samples.max(1);
            Ok((0..=samples)
                .filter_map(|i| {
                    let t = i as f32 / samples as f32;
                    let tool = [
                        start[0] + (end[0] - start[0]) * t,
                        start[1] + (end[1] - start[1]) * t,
                    ];
                    arm.links_at(tool)
                })
                .collect())
        })
    }

    /// Moves the tool in a straight line to `target`, taking the time its trapezoidal
    /// profile takes.
    pub async fn move_to(&self, target: Target) -> Result<(), DeviceError> {
        let _turn = self.sim.turn(self.id).await;
        let robot = self.id;
        let duration = self.sim.with(|world, now| {
            let to = world.reachable(robot, target)?;
            Ok(world.arm(robot).start_move(now, to))
        })?;
        self.sim.wake_stepper();
        let outcome = self.spend(duration, true).await;
        self.sim.with(|world, now| {
            let (arm, physics) = world.arm_and_physics(robot);
            arm.stop(now, physics);
        });
        outcome
    }

    /// Grasps a chip from `feeder`, where the tool must be. Fails on an empty feeder, which
    /// calls the operator: it is refilled [`REFILL_DELAY`](crate::layout::REFILL_DELAY) later.
    pub async fn grasp(&self, feeder: FeederId) -> Result<u32, DeviceError> {
        let _turn = self.sim.turn(self.id).await;
        self.require_at(Target::Feeder(feeder), "feeder")?;
        self.spend_working(GRASP_TIME).await?;
        let robot = self.id;
        self.sim.with(|world, now| {
            let feeder = world
                .feeder(feeder, now)
                .ok_or(DeviceError::UnknownFeeder { feeder })?;
            if feeder.stock == 0 {
                let (id, chip) = (feeder.id, feeder.chip);
                world.report_empty(id, now);
                return Err(DeviceError::EmptyFeeder { feeder: id, chip });
            }
            feeder.stock -= 1;
            let chip = feeder.chip;
            world.arm(robot).holding = Some(Held::Chip(chip));
            Ok(chip)
        })
    }

    /// Inserts the chip it holds into the card on the pallet its station holds, where the
    /// tool is over the card (the simulation records the place, measured against the
    /// pallet's pose).
    pub async fn insert(&self) -> Result<u32, DeviceError> {
        let _turn = self.sim.turn(self.id).await;
        let robot = self.id;
        let over_card = self
            .sim
            .with(|world, now| world.tool_on_card(robot, now).is_some());
        if !over_card {
            return Err(DeviceError::NotThere { robot, at: "card" });
        }
        let Some(Held::Chip(chip)) = self.sim.with(|world, _| world.arm(robot).holding) else {
            return Err(DeviceError::NothingHeld { robot });
        };
        self.spend_working(INSERT_TIME).await?;
        self.on_pallet(Station::Chip, |world, pallet_line, now| {
            let on_card = world
                .tool_on_card(robot, now)
                .ok_or(DeviceError::NotThere { robot, at: "card" })?;
            let pallet = world.held_pallet(pallet_line, Station::Chip)?;
            if !pallet.screwed {
                return Err(DeviceError::NotReady {
                    line: pallet_line,
                    missing: "screwed card",
                });
            }
            pallet.chips += 1;
            let pallet = pallet.id;
            world.arm(robot).holding = None;
            Ok(SimEvent {
                at: now,
                kind: SimEventKind::ChipInserted {
                    line: pallet_line,
                    pallet,
                    chip,
                    on_card,
                },
            })
        })?;
        Ok(chip)
    }

    /// Picks a blank card from the magazine, where the tool must be.
    pub async fn pick_card(&self) -> Result<(), DeviceError> {
        let _turn = self.sim.turn(self.id).await;
        self.require_at(Target::Magazine, "magazine")?;
        self.spend_working(PICK_CARD_TIME).await?;
        let robot = self.id;
        self.sim
            .with(|world, _| world.arm(robot).holding = Some(Held::Card));
        Ok(())
    }

    /// Lays the card it holds on the pallet its station holds.
    pub async fn place_card(&self) -> Result<(), DeviceError> {
        let _turn = self.sim.turn(self.id).await;
        let robot = self.id;
        self.require_at(Target::Card, "card")?;
        if self.sim.with(|world, _| world.arm(robot).holding) != Some(Held::Card) {
            return Err(DeviceError::NothingHeld { robot });
        }
        self.spend_working(PLACE_CARD_TIME).await?;
        self.on_pallet(Station::Load, |world, line, now| {
            let pallet = world.held_pallet(line, Station::Load)?;
            if pallet.card {
                return Err(DeviceError::NotReady {
                    line,
                    missing: "free place for a card",
                });
            }
            pallet.card = true;
            let pallet = pallet.id;
            world.arm(robot).holding = None;
            Ok(SimEvent {
                at: now,
                kind: SimEventKind::CardPlaced { line, pallet },
            })
        })
    }

    /// Screws the card on the pallet its station holds to the pallet.
    pub async fn screw(&self) -> Result<(), DeviceError> {
        let _turn = self.sim.turn(self.id).await;
        self.require_at(Target::Card, "card")?;
        self.spend_working(SCREW_TIME).await?;
        self.on_pallet(Station::Load, |world, line, now| {
            let pallet = world.held_pallet(line, Station::Load)?;
            if !pallet.card {
                return Err(DeviceError::NotReady {
                    line,
                    missing: "card",
                });
            }
            pallet.screwed = true;
            let pallet = pallet.id;
            Ok(SimEvent {
                at: now,
                kind: SimEventKind::CardScrewed { line, pallet },
            })
        })
    }

    fn require_at(&self, target: Target, what: &'static str) -> Result<(), DeviceError> {
        let robot = self.id;
        let there = self.sim.with(|world, now| {
            world.point_of(robot, target)?;
            Ok::<_, DeviceError>(world.is_at(robot, target, now))
        })?;
        if there {
            Ok(())
        } else {
            Err(DeviceError::NotThere { robot, at: what })
        }
    }

    /// Applies a step's effect to the pallet at the robot's station, recording the fact.
    fn on_pallet(
        &self,
        station: Station,
        effect: impl FnOnce(
            &mut World,
            crate::ids::Line,
            imrs_ports::Instant,
        ) -> Result<SimEvent, DeviceError>,
    ) -> Result<(), DeviceError> {
        debug_assert_eq!(World::station_of(self.id), station);
        let line = self.id.line;
        let fact = self.sim.with(|world, now| effect(world, line, now))?;
        self.sim.record(fact);
        Ok(())
    }

    /// Spends `duration` working at a place, counted as working time.
    async fn spend_working(&self, duration: Duration) -> Result<(), DeviceError> {
        self.spend(duration, false).await
    }

    /// Spends `duration` moving or working, unless an injected fault strikes first; the time
    /// actually spent is counted either way.
    async fn spend(&self, duration: Duration, moving: bool) -> Result<(), DeviceError> {
        let start = self.sim.now();
        let outcome = self.busy(duration).await;
        let spent = self.sim.now().saturating_duration_since(start);
        let robot = self.id;
        self.sim.with(|world, _| world.spend(robot, spent, moving));
        outcome
    }

    /// Spends `duration`, unless an injected fault strikes first.
    async fn busy(&self, duration: Duration) -> Result<(), DeviceError> {
        let robot = self.id;
        let (start, fault) = self
            .sim
            .with(|world, now| (now, world.take_robot_fault(robot, now + duration)));
        let clock = self.sim.clock();
        match fault {
            None => {
                clock.sleep(duration).await;
                Ok(())
            }
            Some(at) => {
                clock.sleep_until(at.max(start)).await;
                Err(DeviceError::RobotFault { robot })
            }
        }
    }
}
