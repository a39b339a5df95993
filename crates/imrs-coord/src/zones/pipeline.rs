//! The arm controller's pipeline: trajectory points computed ahead and checked for zone
//! conflicts before the arm moves through them.

use std::collections::{BTreeSet, VecDeque};

use imrs_ports::Name;

use super::{Answer, Resources, ZoneError};

/// What the pipeline tells the arm's dynamic controller.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Move to this point (the trajectory goes on, or resumes after a STOP_C).
    Continue([f32; 3]),
    /// STOP_C: stop; a point `offset` ahead enters this zone, which is not available. The
    /// arm stops before it: the offset covers its stopping distance.
    StopC(Name),
    /// TRAJECTORY_END: the last point is reached.
    TrajectoryEnd,
}

/// Points computed ahead in a circular queue of length `offset + 2` (the seed's): while
/// the arm acts on point `i - offset`, point `i` is checked. `offset` is the number of
/// points the arm needs to stop from full speed.
#[derive(Debug, Clone)]
pub struct Pipeline {
    robot: Name,
    offset: usize,
    ahead: VecDeque<[f32; 3]>,
    rest: VecDeque<[f32; 3]>,
    /// Zones granted for the points queued ahead or acted on.
    granted: BTreeSet<Name>,
    /// Zones the arm is in now.
    inside: BTreeSet<Name>,
}

impl Pipeline {
    /// A trajectory of `points` (spaced `spacing` m apart) for `robot`, moving at `speed`
    /// m/s and stopping at `deceleration` m/s²: the offset is the stopping distance
    /// `speed² / (2 · deceleration)` in points, rounded up.
    pub fn new(
        robot: impl Into<Name>,
        points: impl IntoIterator<Item = [f32; 3]>,
        speed: f32,
        deceleration: f32,
        spacing: f32,
    ) -> Self {
        let stopping = speed * speed / (2.0 * deceleration);
        Self {
            robot: robot.into(),
            offset: (stopping / spacing).ceil().max(1.0) as usize,
            ahead: VecDeque::new(),
            rest: points.into_iter().collect(),
            granted: BTreeSet::new(),
            inside: BTreeSet::new(),
        }
    }

    /// The same pipeline with an offset chosen rather than computed from the arm's
    /// stopping distance: 0 checks a point only as the arm is about to move towards it (a
    /// zone asked for at its border), and one too small is a negative control.
    pub fn with_offset(mut self, offset: usize) -> Self {
        self.offset = offset;
        self
    }

    /// The points between the one acted on and the one checked.
    pub fn offset(&self) -> usize {
        self.offset
    }

    /// The length of the circular queue: `offset + 2`.
    pub fn capacity(&self) -> usize {
        self.offset + 2
    }

    /// What the arm must do next, with `zones_at` saying which zones a point lies in:
    /// compute and check points until the queue is full, then act on its oldest.
    ///
    /// - [`Next::Request`]: a checked point enters a zone not yet granted. Ask the
    ///   coordinator; on a grant tell [`Pipeline::granted`] and call again; on *sleep*
    ///   the arm stops where it is (STOP_C) — the queue holds the points between — until
    ///   woken, then asks again.
    /// - [`Next::Move`]: move to the point, then release the zones it names: the arm has
    ///   left them once there, and no point ahead needs them. (Not before: on its way to
    ///   the point the gripper is still in them.)
    /// - [`Next::End`]: the trajectory's end (TRAJECTORY_END).
    ///
    /// Free of any transport, so an arm module drives it over ports and [`Pipeline::step`]
    /// against a [`Resources`] table directly.
    pub fn next<Z>(&mut self, zones_at: Z) -> Next
    where
        Z: Fn([f32; 3]) -> Vec<Name>,
    {
        while self.ahead.len() < self.capacity() {
            let Some(&point) = self.rest.front() else {
                break;
            };
            if let Some(zone) = zones_at(point)
                .into_iter()
                .find(|zone| !self.granted.contains(zone))
            {
                return Next::Request(zone);
            }
            self.ahead.push_back(point);
            self.rest.pop_front();
        }
        let Some(point) = self.ahead.pop_front() else {
            return Next::End;
        };
        let now_in: BTreeSet<Name> = zones_at(point).into_iter().collect();
        let mut release = Vec::new();
        for left in self.inside.difference(&now_in) {
            // Still needed by a point queued ahead: keep it.
            if self.ahead.iter().any(|p| zones_at(*p).contains(left)) {
                continue;
            }
            release.push(left.clone());
        }
        for left in &release {
            self.granted.remove(left);
        }
        self.inside = now_in;
        Next::Move { point, release }
    }

    /// The coordinator granted `zone`.
    pub fn granted(&mut self, zone: Name) {
        self.granted.insert(zone);
    }

    /// The zones the arm holds now: granted, for the points it is at or has queued.
    pub fn holding(&self) -> impl Iterator<Item = &Name> {
        self.granted.iter()
    }

    /// One step against `table` itself: [`Pipeline::next`], with every request asked of
    /// the table and every release told to it. Returns the command for the arm's
    /// dynamic controller, and who the releases woke.
    pub fn step(&mut self, table: &mut Resources) -> Result<(Command, Vec<Name>), ZoneError> {
        loop {
            match self.next(|point| table.zones_at(point)) {
                Next::Request(zone) => {
                    match table.request_move(self.robot.as_str(), zone.as_str())? {
                        Answer::Grant => self.granted(zone),
                        Answer::Sleep => return Ok((Command::StopC(zone), Vec::new())),
                    }
                }
                Next::Move { point, release } => {
                    let mut woken = Vec::new();
                    for zone in release {
                        woken.extend(table.release(self.robot.as_str(), zone.as_str())?);
                    }
                    return Ok((Command::Continue(point), woken));
                }
                Next::End => {
                    table.trajectory_end(self.robot.as_str())?;
                    return Ok((Command::TrajectoryEnd, Vec::new()));
                }
            }
        }
    }
}

/// What [`Pipeline::next`] asks of the arm.
#[derive(Debug, Clone, PartialEq)]
pub enum Next {
    /// Ask the coordinator for this zone before going on.
    Request(Name),
    /// Move to the point, then release these zones.
    Move {
        /// The point.
        point: [f32; 3],
        /// The zones left behind.
        release: Vec<Name>,
    },
    /// The last point is reached.
    End,
}
