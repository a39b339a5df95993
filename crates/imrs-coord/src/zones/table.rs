//! The coordinator's table of zones and tools: who holds, who is inside, who moves, who
//! sleeps.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::fmt;

use imrs_ports::Name;
use parry3d::math::{Pose, Vector};
use parry3d::query::PointQuery;
use parry3d::shape::Cuboid;

/// How a zone is shared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ZoneKind {
    /// One robot inside at a time.
    Exclusive,
    /// Several robots inside, one moving at a time.
    Shared,
}

/// A zone, defined before the cell starts: its name, how it is shared, and where it is.
#[derive(Debug, Clone)]
pub struct ZoneDef {
    /// Its name.
    pub name: Name,
    /// How it is shared.
    pub kind: ZoneKind,
    shape: Cuboid,
    pose: Pose,
}

impl ZoneDef {
    /// A box-shaped zone centred at `centre` with half-extents `half`, in metres.
    pub fn boxed(name: impl Into<Name>, kind: ZoneKind, centre: [f32; 3], half: [f32; 3]) -> Self {
        Self {
            name: name.into(),
            kind,
            shape: Cuboid::new(Vector::new(half[0], half[1], half[2])),
            pose: Pose::translation(centre[0], centre[1], centre[2]),
        }
    }

    /// Whether a ball of `radius` at `point` (a gripper) reaches into the zone: its
    /// distance to the zone's box, by parry3d, is at most `radius`.
    pub fn touches(&self, point: [f32; 3], radius: f32) -> bool {
        self.shape
            .distance_to_point(&self.pose, Vector::new(point[0], point[1], point[2]), true)
            <= radius
    }

    /// Whether `point` lies in the zone (a parry3d point query).
    pub fn contains(&self, point: [f32; 3]) -> bool {
        self.shape
            .contains_point(&self.pose, Vector::new(point[0], point[1], point[2]))
    }
}

/// What the coordinator answers a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// Shared zone grant (or the tool, or the exclusive zone): go on.
    Grant,
    /// Sleep: stop at the border until woken.
    Sleep,
}

/// A request the table cannot take: it names what was wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ZoneError {
    /// No zone or tool of this name was defined before start.
    Unknown(Name),
    /// No robot of this name.
    UnknownRobot(Name),
    /// Zones change only while every robot is stopped: these are moving.
    RobotsMoving(Vec<Name>),
    /// This robot told a position, or asked about a way, that is no place: a coordinate
    /// that is not a finite number.
    NoPlace(Name),
}

impl fmt::Display for ZoneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Unknown(name) => write!(f, "no zone or tool {name} was defined before start"),
            Self::UnknownRobot(name) => write!(f, "no robot {name} in the cell"),
            Self::NoPlace(name) => {
                write!(
                    f,
                    "robot {name} gave a position that is no place (not finite)"
                )
            }
            Self::RobotsMoving(robots) => {
                write!(
                    f,
                    "zones change only while every robot is stopped; moving: "
                )?;
                let names: Vec<&str> = robots.iter().map(Name::as_str).collect();
                f.write_str(&names.join(", "))
            }
        }
    }
}

impl std::error::Error for ZoneError {}

/// One zone's or tool's state.
#[derive(Debug, Clone, Default)]
struct Held {
    /// Robots inside (a tool: its holder).
    inside: BTreeSet<Name>,
    /// The robot that may move inside (shared zones).
    moving: Option<Name>,
    /// Robots asleep at the border, in the order they asked.
    sleeping: VecDeque<Name>,
}

/// The coordinator's table: the zones and tools defined before start, which are active,
/// and who holds, is inside, moves and sleeps.
#[derive(Debug, Clone)]
pub struct Resources {
    zones: Vec<ZoneDef>,
    active: Vec<bool>,
    held: BTreeMap<Name, Held>,
    tools: BTreeSet<Name>,
    /// Robots, and whether each is moving.
    robots: BTreeMap<Name, bool>,
}

impl Resources {
    /// The table for `zones` (all active), `tools` and `robots` (all stopped).
    pub fn new<R: Into<Name>, T: Into<Name>>(
        zones: impl IntoIterator<Item = ZoneDef>,
        tools: impl IntoIterator<Item = T>,
        robots: impl IntoIterator<Item = R>,
    ) -> Self {
        let zones: Vec<ZoneDef> = zones.into_iter().collect();
        let tools: BTreeSet<Name> = tools.into_iter().map(Into::into).collect();
        let held = zones
            .iter()
            .map(|zone| zone.name.clone())
            .chain(tools.iter().cloned())
            .map(|name| (name, Held::default()))
            .collect();
        Self {
            active: vec![true; zones.len()],
            zones,
            held,
            tools,
            robots: robots.into_iter().map(|r| (r.into(), false)).collect(),
        }
    }

    /// Whether `name` is a zone defined before start: refused by name if not.
    pub fn check_zone(&self, name: &str) -> Result<(), ZoneError> {
        self.zone(name).map(drop)
    }

    fn zone(&self, name: &str) -> Result<usize, ZoneError> {
        self.zones
            .iter()
            .position(|zone| zone.name == name)
            .ok_or_else(|| ZoneError::Unknown(name.into()))
    }

    fn robot(&self, name: &str) -> Result<Name, ZoneError> {
        let name = Name::from(name);
        if self.robots.contains_key(&name) {
            Ok(name)
        } else {
            Err(ZoneError::UnknownRobot(name))
        }
    }

    fn held(&mut self, resource: &str) -> Result<&mut Held, ZoneError> {
        self.held
            .get_mut(&Name::from(resource))
            .ok_or_else(|| ZoneError::Unknown(resource.into()))
    }

    /// The zones a point lies in, of the active ones.
    pub fn zones_at(&self, point: [f32; 3]) -> Vec<Name> {
        self.zones
            .iter()
            .zip(&self.active)
            .filter(|(zone, active)| **active && zone.contains(point))
            .map(|(zone, _)| zone.name.clone())
            .collect()
    }

    /// *Request to move in a shared zone*: `Grant`, or `Sleep` at the border (queued).
    /// An inactive zone restricts nothing.
    pub fn request_move(&mut self, robot: &str, zone: &str) -> Result<Answer, ZoneError> {
        let robot = self.robot(robot)?;
        let index = self.zone(zone)?;
        if !self.active[index] {
            self.robots.insert(robot, true);
            return Ok(Answer::Grant);
        }
        let kind = self.zones[index].kind;
        let held = self.held(zone)?;
        let free = match kind {
            ZoneKind::Exclusive => held.inside.iter().all(|r| *r == robot),
            ZoneKind::Shared => held.moving.as_ref().is_none_or(|r| *r == robot),
        };
        // A robot already inside goes before those queued at the border: it is on its
        // way out, and making it wait for them would have each wait for the other.
        let its_turn = held.inside.contains(&robot)
            || held.sleeping.is_empty()
            || held.sleeping.front() == Some(&robot);
        if free && its_turn {
            held.sleeping.retain(|r| *r != robot);
            held.inside.insert(robot.clone());
            if kind == ZoneKind::Shared {
                held.moving = Some(robot.clone());
            }
            self.robots.insert(robot, true);
            Ok(Answer::Grant)
        } else {
            if !held.sleeping.contains(&robot) {
                held.sleeping.push_back(robot.clone());
            }
            self.robots.insert(robot, false);
            Ok(Answer::Sleep)
        }
    }

    /// *Position information*: `robot` stopped inside `zone`, away from its end point. In a
    /// shared zone it gives up moving there, so another may move; returns who is woken.
    pub fn stopped_inside(&mut self, robot: &str, zone: &str) -> Result<Vec<Name>, ZoneError> {
        let robot = self.robot(robot)?;
        self.robots.insert(robot.clone(), false);
        let held = self.held(zone)?;
        if held.moving.as_ref() == Some(&robot) {
            held.moving = None;
        }
        Ok(self.wake(zone))
    }

    /// *Zone release*: `robot` left `zone`. Returns who is woken.
    pub fn release(&mut self, robot: &str, zone: &str) -> Result<Vec<Name>, ZoneError> {
        let robot = self.robot(robot)?;
        let held = self.held(zone)?;
        held.inside.remove(&robot);
        if held.moving.as_ref() == Some(&robot) {
            held.moving = None;
        }
        Ok(self.wake(zone))
    }

    /// *Trajectory end*: `robot` stopped.
    pub fn trajectory_end(&mut self, robot: &str) -> Result<(), ZoneError> {
        let robot = self.robot(robot)?;
        self.robots.insert(robot, false);
        Ok(())
    }

    /// Asks for a tool: `Grant`, or `Sleep` until its holder puts it down.
    pub fn request_tool(&mut self, robot: &str, tool: &str) -> Result<Answer, ZoneError> {
        let robot = self.robot(robot)?;
        if !self.tools.contains(&Name::from(tool)) {
            return Err(ZoneError::Unknown(tool.into()));
        }
        let held = self.held(tool)?;
        let its_turn = held.inside.contains(&robot)
            || held.sleeping.is_empty()
            || held.sleeping.front() == Some(&robot);
        if held.inside.iter().all(|r| *r == robot) && its_turn {
            held.sleeping.retain(|r| *r != robot);
            held.inside.insert(robot);
            Ok(Answer::Grant)
        } else {
            if !held.sleeping.contains(&robot) {
                held.sleeping.push_back(robot);
            }
            Ok(Answer::Sleep)
        }
    }

    /// Whether `name` is a tool.
    pub fn is_tool(&self, name: &str) -> bool {
        self.tools.contains(&Name::from(name))
    }

    /// Puts a tool down; returns who is woken.
    pub fn release_tool(&mut self, robot: &str, tool: &str) -> Result<Vec<Name>, ZoneError> {
        self.release_held(robot, tool)
    }

    fn release_held(&mut self, robot: &str, resource: &str) -> Result<Vec<Name>, ZoneError> {
        let robot = self.robot(robot)?;
        self.held(resource)?.inside.remove(&robot);
        Ok(self.wake(resource))
    }

    /// Wakes the first sleeper of `resource` if it may go now (it will ask again).
    fn wake(&mut self, resource: &str) -> Vec<Name> {
        let exclusive = self
            .zone(resource)
            .map_or(true, |i| self.zones[i].kind == ZoneKind::Exclusive);
        let Some(held) = self.held.get(&Name::from(resource)) else {
            return Vec::new();
        };
        let free = if exclusive {
            held.inside.is_empty()
        } else {
            held.moving.is_none()
        };
        match held.sleeping.front() {
            Some(first) if free => vec![first.clone()],
            _ => Vec::new(),
        }
    }

    /// The *active zone grant*: activates or deactivates `zone` — refused, naming them,
    /// while any robot moves.
    pub fn set_active(&mut self, zone: &str, active: bool) -> Result<(), ZoneError> {
        let index = self.zone(zone)?;
        let moving: Vec<Name> = self
            .robots
            .iter()
            .filter(|(_, moving)| **moving)
            .map(|(robot, _)| robot.clone())
            .collect();
        if !moving.is_empty() {
            return Err(ZoneError::RobotsMoving(moving));
        }
        self.active[index] = active;
        Ok(())
    }

    /// Who holds `resource` (inside an exclusive zone, or holding a tool), and who sleeps
    /// waiting for it: the edges of the wait-for graph.
    pub(crate) fn exclusive_waits(&self) -> Vec<(Name, Vec<Name>, Vec<Name>)> {
        self.held
            .iter()
            .filter(|(name, _)| {
                self.tools.contains(*name)
                    || self.zones.iter().zip(&self.active).any(|(z, &active)| {
                        active && z.name == **name && z.kind == ZoneKind::Exclusive
                    })
            })
            .map(|(name, held)| {
                (
                    name.clone(),
                    held.inside.iter().cloned().collect(),
                    held.sleeping.iter().cloned().collect(),
                )
            })
            .collect()
    }

    /// Movement rights in shared zones, as waits: for each shared zone, the robot that
    /// moves there and the robots asleep at its border.
    pub(crate) fn shared_waits(&self) -> Vec<(Name, Vec<Name>, Vec<Name>)> {
        self.held
            .iter()
            .filter(|(name, _)| {
                self.zones
                    .iter()
                    .zip(&self.active)
                    .any(|(z, &active)| active && z.name == **name && z.kind == ZoneKind::Shared)
            })
            .map(|(name, held)| {
                (
                    name.clone(),
                    held.moving.iter().cloned().collect(),
                    held.sleeping.iter().cloned().collect(),
                )
            })
            .collect()
    }

    /// `robot` backs off to resolve a deadlock: it waits for nothing any more (out of every
    /// queue) and is stopped (it moves in no shared zone), but the zones it is inside and
    /// the tools it holds stay its own until it says it has left them or put them down
    /// ([`release`](Self::release), [`release_tool`](Self::release_tool)), as it really
    /// has. Returns who is woken.
    pub fn stop_waiting(&mut self, robot: &str) -> Result<Vec<Name>, ZoneError> {
        let name = self.robot(robot)?;
        self.robots.insert(name, false);
        self.leave_queues(robot, false)
    }

    /// `robot` sleeps no more: it leaves every queue it is in, and keeps what it holds,
    /// its rights to move in shared zones too (to get out of the way, it must move).
    /// Returns who is woken: the next in a queue it headed.
    pub fn stop_sleeping(&mut self, robot: &str) -> Result<Vec<Name>, ZoneError> {
        self.leave_queues(robot, true)
    }

    /// `robot` leaves every queue, and its rights to move unless `keep_moving`; who is
    /// woken: the next in a queue it headed, or at a zone it no longer moves in.
    fn leave_queues(&mut self, robot: &str, keep_moving: bool) -> Result<Vec<Name>, ZoneError> {
        let robot = self.robot(robot)?;
        let names: Vec<Name> = self.held.keys().cloned().collect();
        let mut woken = Vec::new();
        for name in names {
            let held = self.held(name.as_str())?;
            let was_first = held.sleeping.front() == Some(&robot);
            held.sleeping.retain(|r| *r != robot);
            let stops_moving = !keep_moving && held.moving.as_ref() == Some(&robot);
            if stops_moving {
                held.moving = None;
            }
            if was_first || stops_moving {
                woken.extend(self.wake(name.as_str()));
            }
        }
        Ok(woken)
    }

    /// Takes `robot` out of every queue and resource it holds at once, as when it is taken
    /// out of the cell; returns who is woken. A robot that backs off from a deadlock still
    /// holds what it is inside: see [`stop_waiting`](Self::stop_waiting).
    pub fn back_off(&mut self, robot: &str) -> Result<Vec<Name>, ZoneError> {
        let robot = self.robot(robot)?;
        let names: Vec<Name> = self.held.keys().cloned().collect();
        let mut woken = Vec::new();
        for name in names {
            let held = self.held(name.as_str())?;
            let had = held.inside.remove(&robot);
            held.sleeping.retain(|r| *r != robot);
            if held.moving.as_ref() == Some(&robot) {
                held.moving = None;
            }
            if had {
                woken.extend(self.wake(name.as_str()));
            }
        }
        Ok(woken)
    }
}
