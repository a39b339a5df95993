//! A device call and its answer as they lie in shared memory between the world's process and
//! a line's: fixed-size `#[repr(C)]` records, with every value of the simulation's own types
//! encoded and decoded here, so that a record a peer garbled decodes to `None`, never to a
//! wrong command.

use imrs_ipc::{FromBytes, ZeroCopySend};
use imrs_sim::{DeviceError, FeederId, Line, PalletId, Release, RobotId, Role, Station, Target};
use serde::{Deserialize, Serialize};

/// What a line's module asks of a device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Op {
    /// A robot moves its tool to a target.
    Move(Target),
    /// A robot grasps a chip from a feeder.
    Grasp(FeederId),
    /// A robot inserts the chip it holds.
    Insert,
    /// The load robot picks a card from the magazine.
    PickCard,
    /// The load robot lays its card on the pallet.
    PlaceCard,
    /// The screw robot screws the card down.
    Screw,
    /// The gate releases a pallet.
    ReleasePallet,
    /// A relay waits for a pallet to be held in place.
    WaitInPlace,
    /// A relay lets its pallet go.
    LetGo,
    /// A relay's jammed pallet is taken off the line.
    ClearJam,
    /// A robot computes the space its arm sweeps from `from` (or where its tool is) to
    /// `to`, in `samples` steps: at most [`MAX_SWEEP_SAMPLES`], the answer's room.
    Sweep {
        /// Where the move starts; `None`: where the tool is.
        from: Option<Target>,
        /// Where it ends.
        to: Target,
        /// In how many steps.
        samples: u32,
    },
}

/// The most steps a sweep that crosses processes has: its poses (one more) fill an answer.
pub const MAX_SWEEP_SAMPLES: usize = SWEEP_POSES - 1;

/// The poses an answer has room for.
const SWEEP_POSES: usize = 32;

/// One pose of a sweep: the arm's base, elbow and tool in the working plane.
pub type Pose = [[f32; 2]; 3];

/// An [`Op`] in shared memory.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes, Serialize, Deserialize,
)]
#[repr(C)]
#[type_name("cell_example::DeviceCall")]
pub struct DeviceCall {
    op: u32,
    target: u32,
    feeder: u32,
    at: [f32; 2],
    /// A sweep's start: [`NO_TARGET`], or a target as `target` is.
    from: u32,
    from_feeder: u32,
    from_at: [f32; 2],
    samples: u32,
    /// The run of the caller's line process (see [`crate::zone_asker`]): the world heeds no
    /// call of a run before the latest it has heard from.
    run: u32,
}

const MOVE: u32 = 1;
const GRASP: u32 = 2;
const INSERT: u32 = 3;
const PICK_CARD: u32 = 4;
const PLACE_CARD: u32 = 5;
const SCREW: u32 = 6;
const RELEASE_PALLET: u32 = 7;
const WAIT_IN_PLACE: u32 = 8;
const LET_GO: u32 = 9;
const CLEAR_JAM: u32 = 10;
const SWEEP: u32 = 11;

const HOME: u32 = 0;
const FEEDER: u32 = 1;
const CARD: u32 = 2;
const ON_CARD: u32 = 3;
const MAGAZINE: u32 = 4;
const POINT: u32 = 5;
/// A sweep from where the tool is.
const NO_TARGET: u32 = u32::MAX;

/// `target`, encoded: its kind, its feeder and its point.
fn encode_target(target: Target) -> (u32, u32, [f32; 2]) {
    match target {
        Target::Home => (HOME, 0, [0.0; 2]),
        Target::Feeder(feeder) => (FEEDER, u32::from(feeder.0), [0.0; 2]),
        Target::Card => (CARD, 0, [0.0; 2]),
        Target::OnCard(at) => (ON_CARD, 0, at),
        Target::Magazine => (MAGAZINE, 0, [0.0; 2]),
        Target::Point(at) => (POINT, 0, at),
    }
}

/// The target encoded; `None` for a kind or feeder no [`encode_target`] wrote.
fn decode_target(kind: u32, feeder: u32, at: [f32; 2]) -> Option<Target> {
    Some(match kind {
        HOME => Target::Home,
        FEEDER => Target::Feeder(FeederId(u8::try_from(feeder).ok()?)),
        CARD => Target::Card,
        ON_CARD => Target::OnCard(at),
        MAGAZINE => Target::Magazine,
        POINT => Target::Point(at),
        _ => return None,
    })
}

impl DeviceCall {
    /// `op`, encoded.
    pub fn new(op: Op) -> Self {
        let mut call = Self::default();
        call.op = match op {
            Op::Move(target) => {
                (call.target, call.feeder, call.at) = encode_target(target);
                MOVE
            }
            Op::Grasp(feeder) => {
                call.feeder = u32::from(feeder.0);
                GRASP
            }
            Op::Insert => INSERT,
            Op::PickCard => PICK_CARD,
            Op::PlaceCard => PLACE_CARD,
            Op::Screw => SCREW,
            Op::ReleasePallet => RELEASE_PALLET,
            Op::WaitInPlace => WAIT_IN_PLACE,
            Op::LetGo => LET_GO,
            Op::ClearJam => CLEAR_JAM,
            Op::Sweep { from, to, samples } => {
                (call.target, call.feeder, call.at) = encode_target(to);
                (call.from, call.from_feeder, call.from_at) =
                    from.map_or((NO_TARGET, 0, [0.0; 2]), encode_target);
                call.samples = samples;
                SWEEP
            }
        };
        call
    }

    /// The call, sent from `run` of its line's process.
    pub fn in_run(mut self, run: u32) -> Self {
        self.run = run;
        self
    }

    /// The run of its line's process it was sent from.
    pub fn run(&self) -> u32 {
        self.run
    }

    /// The call it encodes; `None` for a record no [`DeviceCall::new`] wrote.
    pub fn op(&self) -> Option<Op> {
        let feeder = || u8::try_from(self.feeder).ok().map(FeederId);
        Some(match self.op {
            MOVE => Op::Move(decode_target(self.target, self.feeder, self.at)?),
            GRASP => Op::Grasp(feeder()?),
            INSERT => Op::Insert,
            PICK_CARD => Op::PickCard,
            PLACE_CARD => Op::PlaceCard,
            SCREW => Op::Screw,
            RELEASE_PALLET => Op::ReleasePallet,
            WAIT_IN_PLACE => Op::WaitInPlace,
            LET_GO => Op::LetGo,
            CLEAR_JAM => Op::ClearJam,
            SWEEP => Op::Sweep {
                from: match self.from {
                    NO_TARGET => None,
                    kind => Some(decode_target(kind, self.from_feeder, self.from_at)?),
                },
                to: decode_target(self.target, self.feeder, self.at)?,
                samples: self.samples,
            },
            _ => return None,
        })
    }
}

/// How a device call went, in shared memory: a value (a chip number, a pallet), nothing, or
/// the device's error.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes, Serialize, Deserialize,
)]
#[repr(C)]
#[type_name("cell_example::DeviceAnswer")]
pub struct DeviceAnswer {
    status: u32,
    /// A value; for a sweep, how many of `poses` it has.
    value: u32,
    error: [i32; 4],
    poses: [Pose; SWEEP_POSES],
}

const DONE: u32 = 0;
const VALUE: u32 = 1;
const FAILED: u32 = 2;
const MALFORMED: u32 = 3;
const SWEPT: u32 = 4;
const STALE: u32 = 5;

/// What a device answered, decoded.
#[derive(Debug, Clone, PartialEq)]
pub enum Answer {
    /// Done, with no value.
    Done,
    /// Done, with a value.
    Value(u32),
    /// The device refused or failed.
    Failed(DeviceError),
    /// The world could not read the call.
    Malformed,
    /// Not carried out: a call of a run of the line's process that has died since.
    Stale,
    /// A sweep's poses: at most [`MAX_SWEEP_SAMPLES`] + 1.
    Sweep(Vec<Pose>),
}

/// The places a robot can be found not to be at (`DeviceError::NotThere`).
const PLACES: [&str; 3] = ["card", "feeder", "magazine"];
/// What a pallet can be missing (`DeviceError::NotReady`).
const MISSING: [&str; 3] = ["card", "screwed card", "free place for a card"];

impl DeviceAnswer {
    /// `answer`, encoded.
    pub fn new(answer: &Answer) -> Self {
        match answer {
            Answer::Done => Self::default(),
            Answer::Value(value) => Self {
                status: VALUE,
                value: *value,
                ..Self::default()
            },
            Answer::Failed(error) => Self {
                status: FAILED,
                error: encode_error(error),
                ..Self::default()
            },
            Answer::Sweep(sweep) => {
                let mut answer = Self {
                    status: SWEPT,
                    ..Self::default()
                };
                // The world asks for no more samples than fit (see `MAX_SWEEP_SAMPLES`).
                let poses = sweep.len().min(SWEEP_POSES);
                answer.poses[..poses].copy_from_slice(&sweep[..poses]);
                answer.value = poses as u32;
                answer
            }
            Answer::Malformed => Self {
                status: MALFORMED,
                ..Self::default()
            },
            Answer::Stale => Self {
                status: STALE,
                ..Self::default()
            },
        }
    }

    /// The outcome of an operation that returns `Result<(), DeviceError>`, or `Result<u32,
    /// _>`, or a gate's release, encoded.
    pub fn of<T: Into<Option<u32>>>(outcome: Result<T, DeviceError>) -> Self {
        Self::new(&match outcome {
            Ok(value) => value.into().map_or(Answer::Done, Answer::Value),
            Err(error) => Answer::Failed(error),
        })
    }

    /// A gate's release, encoded: the released pallet, or nothing when the line backed up.
    pub fn of_release(release: Release) -> Self {
        Self::new(&match release {
            Release::Released(pallet) => Answer::Value(pallet.0),
            Release::BackedUp => Answer::Done,
        })
    }

    /// The answer it encodes; `None` for a record no [`DeviceAnswer::new`] wrote.
    pub fn answer(&self) -> Option<Answer> {
        Some(match self.status {
            DONE => Answer::Done,
            VALUE => Answer::Value(self.value),
            FAILED => Answer::Failed(decode_error(self.error)?),
            MALFORMED => Answer::Malformed,
            STALE => Answer::Stale,
            SWEPT => Answer::Sweep(
                self.poses
                    .get(..usize::try_from(self.value).ok()?)?
                    .to_vec(),
            ),
            _ => return None,
        })
    }
}

impl Answer {
    /// A released pallet, or a backed-up line.
    pub fn release(&self) -> Option<Release> {
        match self {
            Answer::Value(pallet) => Some(Release::Released(PalletId(*pallet))),
            Answer::Done => Some(Release::BackedUp),
            Answer::Failed(_) | Answer::Malformed | Answer::Stale | Answer::Sweep(_) => None,
        }
    }
}

fn robot_code(robot: RobotId) -> i32 {
    let role = match robot.role {
        Role::LoadCard => 0,
        Role::ScrewInCard => 1,
        Role::ChipIt => 2,
    };
    line_code(robot.line) * 3 + role
}

fn robot_of(code: i32) -> Option<RobotId> {
    let role = match code.checked_rem(3)? {
        0 => Role::LoadCard,
        1 => Role::ScrewInCard,
        2 => Role::ChipIt,
        _ => return None,
    };
    Some(RobotId::new(line_of(code / 3)?, role))
}

fn line_code(line: Line) -> i32 {
    match line {
        Line::A => 0,
        Line::B => 1,
    }
}

fn line_of(code: i32) -> Option<Line> {
    match code {
        0 => Some(Line::A),
        1 => Some(Line::B),
        _ => None,
    }
}

fn station_code(station: Station) -> i32 {
    match station {
        Station::Load => 0,
        Station::Chip => 1,
    }
}

fn station_of(code: i32) -> Option<Station> {
    match code {
        0 => Some(Station::Load),
        1 => Some(Station::Chip),
        _ => None,
    }
}

fn index_in(table: &[&str], text: &str) -> i32 {
    // A text outside the table (a device grew a new one) crosses as the table's length,
    // which decodes to no text of the table: the error is still refused, not renamed.
    let index = table.iter().position(|entry| *entry == text);
    i32::try_from(index.unwrap_or(table.len())).unwrap_or(i32::MAX)
}

fn text_of(table: &[&'static str], index: i32) -> Option<&'static str> {
    table.get(usize::try_from(index).ok()?).copied()
}

fn encode_error(error: &DeviceError) -> [i32; 4] {
    match *error {
        DeviceError::RobotFault { robot } => [1, robot_code(robot), 0, 0],
        DeviceError::OutOfReach { robot, target } => [2, robot_code(robot), target[0], target[1]],
        DeviceError::OffCard { robot, at } => [3, robot_code(robot), at[0], at[1]],
        DeviceError::UnknownFeeder { feeder } => [4, i32::from(feeder.0), 0, 0],
        DeviceError::EmptyFeeder { feeder, chip } => [
            5,
            i32::from(feeder.0),
            i32::try_from(chip).unwrap_or(i32::MAX),
            0,
        ],
        DeviceError::NotThere { robot, at } => [6, robot_code(robot), index_in(&PLACES, at), 0],
        DeviceError::NothingHeld { robot } => [7, robot_code(robot), 0, 0],
        DeviceError::NoPallet { line, station } => [8, line_code(line), station_code(station), 0],
        DeviceError::NotReady { line, missing } => {
            [9, line_code(line), index_in(&MISSING, missing), 0]
        }
        DeviceError::Jam { line, station } => [10, line_code(line), station_code(station), 0],
    }
}

fn decode_error([kind, a, b, c]: [i32; 4]) -> Option<DeviceError> {
    let feeder = || u8::try_from(a).ok().map(FeederId);
    Some(match kind {
        1 => DeviceError::RobotFault {
            robot: robot_of(a)?,
        },
        2 => DeviceError::OutOfReach {
            robot: robot_of(a)?,
            target: [b, c],
        },
        3 => DeviceError::OffCard {
            robot: robot_of(a)?,
            at: [b, c],
        },
        4 => DeviceError::UnknownFeeder { feeder: feeder()? },
        5 => DeviceError::EmptyFeeder {
            feeder: feeder()?,
            chip: u32::try_from(b).ok()?,
        },
        6 => DeviceError::NotThere {
            robot: robot_of(a)?,
            at: text_of(&PLACES, b)?,
        },
        7 => DeviceError::NothingHeld {
            robot: robot_of(a)?,
        },
        8 => DeviceError::NoPallet {
            line: line_of(a)?,
            station: station_of(b)?,
        },
        9 => DeviceError::NotReady {
            line: line_of(a)?,
            missing: text_of(&MISSING, b)?,
        },
        10 => DeviceError::Jam {
            line: line_of(a)?,
            station: station_of(b)?,
        },
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_call_crosses_and_comes_back_the_same() {
        let ops = [
            Op::Move(Target::Home),
            Op::Move(Target::Feeder(FeederId(3))),
            Op::Move(Target::Card),
            Op::Move(Target::OnCard([0.01, 0.02])),
            Op::Move(Target::Magazine),
            Op::Move(Target::Point([-0.5, 0.25])),
            Op::Grasp(FeederId(2)),
            Op::Insert,
            Op::PickCard,
            Op::PlaceCard,
            Op::Screw,
            Op::ReleasePallet,
            Op::WaitInPlace,
            Op::LetGo,
            Op::ClearJam,
            Op::Sweep {
                from: None,
                to: Target::Feeder(FeederId(1)),
                samples: 12,
            },
            Op::Sweep {
                from: Some(Target::Feeder(FeederId(0))),
                to: Target::OnCard([0.03, 0.04]),
                samples: 31,
            },
        ];
        for op in ops {
            assert_eq!(DeviceCall::new(op).op(), Some(op));
        }
    }

    #[test]
    fn every_device_error_crosses_and_comes_back_the_same() {
        let robot = RobotId::new(Line::B, Role::ChipIt);
        let mut errors = vec![
            DeviceError::RobotFault { robot },
            DeviceError::OutOfReach {
                robot,
                target: [3, -4],
            },
            DeviceError::OffCard { robot, at: [90, 7] },
            DeviceError::UnknownFeeder {
                feeder: FeederId(9),
            },
            DeviceError::EmptyFeeder {
                feeder: FeederId(1),
                chip: 12,
            },
            DeviceError::NothingHeld { robot },
        ];
        errors.extend(PLACES.map(|at| DeviceError::NotThere { robot, at }));
        errors.extend(MISSING.map(|missing| DeviceError::NotReady {
            line: Line::A,
            missing,
        }));
        for station in Station::ALL {
            errors.push(DeviceError::NoPallet {
                line: Line::B,
                station,
            });
            errors.push(DeviceError::Jam {
                line: Line::A,
                station,
            });
        }
        for error in errors {
            let answer = Answer::Failed(error);
            assert_eq!(DeviceAnswer::new(&answer).answer(), Some(answer));
        }
        let sweep = (0..13)
            .map(|i| [[0.0, 0.0], [0.1 * i as f32, 0.2], [0.3, -0.01 * i as f32]])
            .collect();
        for answer in [
            Answer::Done,
            Answer::Value(7),
            Answer::Malformed,
            Answer::Stale,
            Answer::Sweep(sweep),
            Answer::Sweep(Vec::new()),
        ] {
            assert_eq!(DeviceAnswer::new(&answer).answer(), Some(answer.clone()));
        }
    }

    #[test]
    fn a_garbled_record_decodes_to_nothing() {
        let garbled = DeviceCall {
            op: 99,
            ..DeviceCall::default()
        };
        assert_eq!(garbled.op(), None);
        let bad_target = DeviceCall {
            op: MOVE,
            target: 42,
            ..DeviceCall::default()
        };
        assert_eq!(bad_target.op(), None);
        let bad_feeder = DeviceCall {
            op: GRASP,
            feeder: 300,
            ..DeviceCall::default()
        };
        assert_eq!(bad_feeder.op(), None);
        let bad_start = DeviceCall {
            op: SWEEP,
            from: 42,
            ..DeviceCall::default()
        };
        assert_eq!(bad_start.op(), None);
        let too_many_poses = DeviceAnswer {
            status: SWEPT,
            value: SWEEP_POSES as u32 + 1,
            ..DeviceAnswer::default()
        };
        assert_eq!(too_many_poses.answer(), None);
        for error in [
            [0, 0, 0, 0],
            [1, 6, 0, 0],
            [1, -1, 0, 0],
            [6, 0, 17, 0],
            [8, 2, 0, 0],
        ] {
            let answer = DeviceAnswer {
                status: FAILED,
                error,
                ..DeviceAnswer::default()
            };
            assert_eq!(answer.answer(), None, "{error:?}");
        }
    }
}
