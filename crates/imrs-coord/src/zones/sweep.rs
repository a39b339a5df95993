//! Zones that follow the trajectories: each robot reserves the space its links will sweep,
//! and a reservation is granted only where it keeps clear of every other one.

use std::collections::VecDeque;

use imrs_ports::Name;

use super::space::Space;

/// The poses of an arm along a trajectory: base, elbow and tool in the working plane.
pub type Sweep = Vec<[[f32; 2]; 3]>;

/// Reservations of swept space. Where two robots' trajectories do not meet they hold their
/// reservations at the same time; where they do, the later one waits, first come first
/// served. A reservation is the space of the links, `radius` thick, kept `margin` apart.
#[derive(Debug, Clone)]
pub struct Reservations {
    radius: f32,
    margin: f32,
    held: Vec<(Name, Space)>,
    waiting: VecDeque<(Name, Space)>,
}

/// The space of the links of every pose of `sweep`, each `radius` thick.
pub(super) fn space(sweep: &[[[f32; 2]; 3]], radius: f32) -> Space {
    let links = sweep
        .iter()
        .flat_map(|&[base, elbow, tool]| [(base, elbow), (elbow, tool)]);
    Space::new(links, radius)
}

impl Reservations {
    /// Links `radius` thick, kept `margin` apart.
    pub fn new(radius: f32, margin: f32) -> Self {
        Self {
            radius,
            margin,
            held: Vec::new(),
            waiting: VecDeque::new(),
        }
    }

    /// `robot` asks for the space of `sweep`: granted now (true) if it keeps clear of every
    /// reservation held and of every earlier request still waiting; else it waits in turn.
    pub fn request(&mut self, robot: impl Into<Name>, sweep: &Sweep) -> bool {
        let (robot, space) = (robot.into(), space(sweep, self.radius));
        let free = self
            .held
            .iter()
            .chain(&self.waiting)
            .all(|(_, other)| space.clear_of(other, self.margin));
        if free {
            self.held.push((robot, space));
        } else {
            self.waiting.push_back((robot, space));
        }
        free
    }

    /// `robot` is done with its space; returns the waiting robots granted now, in turn.
    pub fn release(&mut self, robot: &str) -> Vec<Name> {
        self.held.retain(|(holder, _)| *holder != robot);
        let mut granted = Vec::new();
        let mut still = VecDeque::new();
        while let Some((waiter, space)) = self.waiting.pop_front() {
            let free = self
                .held
                .iter()
                .chain(&still)
                .all(|(_, other)| space.clear_of(other, self.margin));
            if free {
                granted.push(waiter.clone());
                self.held.push((waiter, space));
            } else {
                still.push_back((waiter, space));
            }
        }
        self.waiting = still;
        granted
    }

    /// `robot` is gone (its process died): what it held and what it asked for are let go
    /// alike; returns the waiting robots granted now, in turn.
    pub fn withdraw(&mut self, robot: &str) -> Vec<Name> {
        self.waiting.retain(|(waiter, _)| *waiter != robot);
        self.release(robot)
    }

    /// Who holds a reservation now.
    pub fn holders(&self) -> Vec<Name> {
        self.held.iter().map(|(robot, _)| robot.clone()).collect()
    }
}
