//! The arm controller's pipeline: trajectory points computed ahead and checked for zone
//! conflicts before the arm moves through them.

use std::collections::{BTreeSet, VecDeque};

use imrs_core::imrs_ports::Name;

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

    /// The points between the one acted on and the one checked.
    pub fn offset(&self) -> usize {
        self.offset
    }

    /// The length of the circular queue: `offset + 2`.
    pub fn capacity(&self) -> usize {
        self.offset + 2
    }

    /// One step: compute and check points until the queue is full, then act on its oldest.
    /// A checked point in a zone not yet granted asks the coordinator; a `Sleep` stops the
    /// arm (STOP_C) where it is. Leaving a zone releases it; returns who that woke too.
    pub fn step(&mut self, table: &mut Resources) -> Result<(Command, Vec<Name>), ZoneError> {
        while self.ahead.len() < self.capacity() {
            let Some(&point) = self.rest.front() else {
                break;
            };
            for zone in table.zones_at(point) {
                if self.granted.contains(&zone) {
                    continue;
                }
                match table.request_move(self.robot.as_str(), zone.as_str())? {
                    Answer::Grant => {
                        self.granted.insert(zone);
                    }
                    Answer::Sleep => return Ok((Command::StopC(zone), Vec::new())),
                }
            }
            self.ahead.push_back(point);
            self.rest.pop_front();
        }
        let Some(point) = self.ahead.pop_front() else {
            table.trajectory_end(self.robot.as_str())?;
            return Ok((Command::TrajectoryEnd, Vec::new()));
        };
        let now_in: BTreeSet<Name> = table.zones_at(point).into_iter().collect();
        let mut woken = Vec::new();
        for left in self.inside.difference(&now_in).cloned().collect::<Vec<_>>() {
            // Still needed by a point queued ahead: keep it.
            if self
                .ahead
                .iter()
                .any(|p| table.zones_at(*p).contains(&left))
            {
                continue;
            }
            self.granted.remove(&left);
            woken.extend(table.release(self.robot.as_str(), left.as_str())?);
        }
        self.inside = now_in;
        Ok((Command::Continue(point), woken))
    }
}
