//! The coordinator's message set: what a robot tells it or asks it about zones and space,
//! what it answers about space, and what it tells a sleeping robot.

use imrs_ports::Name;

use crate::zones::{Pose, Sweep};

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
