//! A robot's side of the coordinator: its ends of the ports, and how it asks for zones,
//! sleeps at a border, brakes and gives its rights up, asks about space and raises alarms.

use imrs_ports::{End, Name, usage};

use super::messages::{Geometry, Message, Seen, Wake};
use crate::zones::{Answer, Pose, Sweep};

/// Why a robot could not have a zone.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refused {
    /// It must back off: it was chosen to resolve a deadlock.
    BackOff,
    /// The coordinator could not be reached, or refused the name.
    Failed(String),
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BackOff => f.write_str("told to back off, the victim of a deadlock"),
            Self::Failed(why) => f.write_str(why),
        }
    }
}

impl std::error::Error for Refused {}

/// A wake-up received, or why none could be.
type Woken = Result<(Wake, imrs_ports::ReplyHandle<()>), imrs_ports::ReceiveError>;

/// Sends `request` on `to` while listening for a wake-up on `wake`, for a robot asleep in
/// the coordinator's books: `None` once the coordinator answered (an answer counts even if
/// the wake-up came as well: the coordinator has acted on it), or the wake-up if it came
/// first, the request withdrawn.
async fn listening<Q: Send + 'static, A: Send + 'static>(
    to: &mut End<(Name, Q), Result<A, String>, usage::Send>,
    wake: &mut End<Wake, (), usage::Receive>,
    request: (Name, Q),
) -> Result<Option<Woken>, Refused> {
    tokio::select! {
        biased;
        told = to.send(request) => {
            told
                .map_err(|error| Refused::Failed(error.to_string()))?
                .map_err(Refused::Failed)?;
            Ok(None)
        }
        woken = wake.receive() => Ok(Some(woken)),
    }
}

/// A robot's ends of the coordinator's ports.
pub struct RobotLink {
    pub(super) robot: Name,
    pub(super) to: End<(Name, Message), Result<Answer, String>, usage::Send>,
    pub(super) space: End<(Name, Geometry), Result<Seen, String>, usage::Send>,
    pub(super) alarm: End<(Name, String), (), usage::Send>,
    pub(super) wake: End<Wake, (), usage::Receive>,
    pub(super) emergency: End<String, (), usage::Receive>,
}

impl RobotLink {
    /// Tells the coordinator `message`; its answer.
    pub async fn tell(&mut self, message: Message) -> Result<Answer, Refused> {
        self.to
            .send((self.robot.clone(), message))
            .await
            .map_err(|error| Refused::Failed(error.to_string()))?
            .map_err(Refused::Failed)
    }

    /// Asks for `zone` (or a tool) until granted, sleeping at the border meanwhile.
    pub async fn acquire(&mut self, zone: &str) -> Result<(), Refused> {
        self.acquire_giving_up(zone, &[]).await.map(drop)
    }

    /// Asks for `zone` (or a tool) until granted, as [`acquire`](Self::acquire) does; but
    /// the robot moves in the shared zones `moving_in`, and if it must sleep at the border,
    /// it first gives up its right to move in each of them, with a position message (it is
    /// stopped inside): the seed's reason why shared zones cannot deadlock. Returns the
    /// zones it gave up, for it to ask again before it moves.
    pub async fn acquire_giving_up(
        &mut self,
        zone: &str,
        moving_in: &[Name],
    ) -> Result<Vec<Name>, Refused> {
        let mut given_up: Vec<Name> = Vec::new();
        loop {
            // One message: the coordinator never waits on a robot that is still telling it
            // something (its wake-ups are rendezvous).
            let giving_up: Vec<Name> = moving_in
                .iter()
                .filter(|shared| !given_up.contains(shared))
                .cloned()
                .collect();
            let request = Message::RequestGivingUp(zone.into(), giving_up.clone());
            match self.tell(request).await? {
                Answer::Grant => return Ok(given_up),
                Answer::Sleep => {
                    given_up.extend(giving_up);
                    let (wake, reply) = self
                        .wake
                        .receive()
                        .await
                        .map_err(|error| Refused::Failed(error.to_string()))?;
                    reply.reply(());
                    if wake == Wake::BackOff {
                        return Err(Refused::BackOff);
                    }
                }
            }
        }
    }

    /// Asks for `zone` (or a tool) while the robot moves, as its pipeline asks for a point
    /// ahead; granted, it goes on. Told to sleep, it stops (each call of `braking` halts it
    /// and resolves after a step, to where its links are then, if it can say, and whether
    /// it stands still; each pose is told as it brakes): an arm cannot stop at once, and
    /// keeps its right to move in the shared zones `moving_in` while it brakes in them.
    /// Stopped, it tells where it is (position information), gives each right up with a
    /// position message, as the seed's robot does, waits to be woken, and asks again.
    /// Returns the zones it gave up, for it to ask again before it moves.
    ///
    /// From the sleep until the wake-up, every message it sends is sent while it listens for
    /// the wake-up: the coordinator waits for a robot it wakes, and one that waited for the
    /// coordinator in turn would leave both waiting.
    pub async fn acquire_stopping<F: Future<Output = (Option<Pose>, bool)>>(
        &mut self,
        zone: &str,
        moving_in: &[Name],
        mut braking: impl FnMut() -> F,
    ) -> Result<Vec<Name>, Refused> {
        let mut given_up: Vec<Name> = Vec::new();
        let mut at_rest = false;
        loop {
            let giving_up: Vec<Name> = if at_rest {
                moving_in
                    .iter()
                    .filter(|shared| !given_up.contains(shared))
                    .cloned()
                    .collect()
            } else {
                Vec::new()
            };
            let request = Message::RequestGivingUp(zone.into(), giving_up.clone());
            if self.tell(request).await? == Answer::Grant {
                return Ok(given_up);
            }
            given_up.extend(giving_up);
            let woken = if at_rest {
                self.wake.receive().await
            } else {
                self.brake_asleep(&mut braking, moving_in, &mut given_up, &mut at_rest)
                    .await?
            };
            let (wake, reply) = woken.map_err(|error| Refused::Failed(error.to_string()))?;
            reply.reply(());
            if wake == Wake::BackOff {
                return Err(Refused::BackOff);
            }
        }
    }

    /// Asleep and braking: each step of `braking` (where its links are after it, and
    /// whether it stands still) told as position information, listening for the wake-up
    /// meanwhile; once it stands still, its rights given up. The wake-up.
    async fn brake_asleep<F: Future<Output = (Option<Pose>, bool)>>(
        &mut self,
        braking: &mut impl FnMut() -> F,
        moving_in: &[Name],
        given_up: &mut Vec<Name>,
        at_rest: &mut bool,
    ) -> Result<Woken, Refused> {
        loop {
            let step = braking();
            let (pose, still) = tokio::select! {
                biased;
                woken = self.wake.receive() => return Ok(woken),
                braked = step => braked,
            };
            if still {
                *at_rest = true;
                return self.give_up_stopped(pose, moving_in, given_up).await;
            }
            if let Some(pose) = pose {
                let at = (self.robot.clone(), Geometry::At(pose));
                if let Some(woken) = listening(&mut self.space, &mut self.wake, at).await? {
                    return Ok(woken);
                }
            }
        }
    }

    /// Stopped while asleep at `pose`: tells where it is, and gives up the right to move in
    /// each of `moving_in`, a position message each, listening for the wake-up meanwhile
    /// ([`listening`]); then waits for it.
    async fn give_up_stopped(
        &mut self,
        pose: Option<Pose>,
        moving_in: &[Name],
        given_up: &mut Vec<Name>,
    ) -> Result<Woken, Refused> {
        if let Some(pose) = pose {
            let at = (self.robot.clone(), Geometry::At(pose));
            if let Some(woken) = listening(&mut self.space, &mut self.wake, at).await? {
                return Ok(woken);
            }
        }
        for shared in moving_in {
            let position = (self.robot.clone(), Message::Position(shared.clone()));
            if let Some(woken) = listening(&mut self.to, &mut self.wake, position).await? {
                return Ok(woken);
            }
            given_up.push(shared.clone());
        }
        Ok(self.wake.receive().await)
    }

    /// Asks the coordinator about space; its answer.
    async fn ask(&mut self, geometry: Geometry) -> Result<Seen, Refused> {
        self.space
            .send((self.robot.clone(), geometry))
            .await
            .map_err(|error| Refused::Failed(error.to_string()))?
            .map_err(Refused::Failed)
    }

    /// Tells the coordinator where its links are now (position information).
    pub async fn at(&mut self, pose: Pose) -> Result<(), Refused> {
        self.ask(Geometry::At(pose)).await.map(drop)
    }

    /// The robots in the way of its links at the next points of its trajectory, where they
    /// last told the coordinator they were: none when the way is clear.
    pub async fn check(&mut self, sweep: Sweep) -> Result<Vec<Name>, Refused> {
        match self.ask(Geometry::Check(sweep)).await? {
            Seen::Blocked(robots) => Ok(robots),
            Seen::Clear => Ok(Vec::new()),
            other => Err(Refused::Failed(format!("a check answered {other:?}"))),
        }
    }

    /// As [`check`](Self::check), for a robot stopped and waiting for its way to clear,
    /// holding only what it is in: a robot asleep in its way that waits for what it holds
    /// is told to back off.
    pub async fn wait_on(&mut self, sweep: Sweep) -> Result<Vec<Name>, Refused> {
        match self.ask(Geometry::Wait(sweep)).await? {
            Seen::Blocked(robots) => Ok(robots),
            Seen::Clear => Ok(Vec::new()),
            other => Err(Refused::Failed(format!("a wait answered {other:?}"))),
        }
    }

    /// The coordinator's alternative trajectory from `from` to `to` round the robots
    /// `around`: the whole way, `from` first, or `None` if there is none.
    pub async fn alternative(
        &mut self,
        from: [f32; 2],
        to: [f32; 2],
        around: Vec<Name>,
    ) -> Result<Option<Vec<[f32; 2]>>, Refused> {
        match self.ask(Geometry::Alternative { from, to, around }).await? {
            Seen::Alternative(way) => Ok(way),
            other => Err(Refused::Failed(format!(
                "an alternative answered {other:?}"
            ))),
        }
    }

    /// Raises an alarm: the coordinator stops every robot.
    pub async fn alarm(&mut self, text: impl Into<String>) -> Result<(), Refused> {
        self.alarm
            .send((self.robot.clone(), text.into()))
            .await
            .map_err(|error| Refused::Failed(error.to_string()))
    }

    /// Waits for an emergency stop; its text.
    pub async fn emergency(&mut self) -> Result<String, Refused> {
        let (text, reply) = self
            .emergency
            .receive()
            .await
            .map_err(|error| Refused::Failed(error.to_string()))?;
        reply.reply(());
        Ok(text)
    }
}
