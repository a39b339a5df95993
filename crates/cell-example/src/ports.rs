//! Every port of the cell, declared as the Appendix declares it, each showing its messages
//! and replies in a recording (`--record`).

use std::fmt;
use std::time::Duration;

use imrs_core::{Cell, Ctx};
use imrs_ports::{AnyUser, BoundedBufferPort, End, Port, PortSpec, SharedClock, WireError, usage};
use imrs_sim::{Line, PalletId};

use crate::carrier::Imported;
use crate::feeder_policy::FeederPolicy;
use crate::names::{
    FEEDER_COORDINATOR, FEEDER_MONITOR, LINE_DOWN, LineNames, ZONE_FREE, ZONE_RELEASE,
    ZONE_REQUEST, ZONE_RESERVE,
};
use crate::reservation::Reservation;
use crate::zone_asker::ZoneAsker;

/// FREQUENCY(TASK_NUM: INTEGER; TIME_FOR_ONE: REAL), through the bounded buffer.
pub type Frequency = BoundedBufferPort<(i32, f64), AnyUser, 2>;
/// LET_1_GO(RC: INTEGER): USAGE=SEND, #USERS=1, TIMEOUT=2 sec.
pub type Let1Go = Port<(), i32, usage::Send, AnyUser, 1>;
/// ASK_CHILD1(RC, NUM_DONE: INTEGER; TIME_FOR_ONE: REAL): USAGE=QUERY.
pub type AskChild1 = Port<(), (i32, u32, f64), usage::Query>;
/// ASK_CHILD2(RC: INTEGER): USAGE=QUERY.
pub type AskChild2 = Port<(), i32, usage::Query>;
/// PALLET_IN_PLACE(): USAGE=RECEIVE, #USERS=1, TIMEOUT=30 SEC (it names the pallet).
pub type PalletInPlace = Port<PalletId, (), usage::Receive, AnyUser, 1>;
/// CARD_IN_PLACE(RC: INTEGER): USAGE=SEND, USERLIST=(SCREW_IN_CARD), TIMEOUT=30 SEC.
pub type CardInPlace = Port<PalletId, i32, usage::Send>;
/// READY_TO_CHIP(): USAGE=RECEIVE, #USERS=1, TIMEOUT=60 SEC (it names the pallet).
pub type ReadyToChip = Port<PalletId, (), usage::Receive, AnyUser, 1>;
/// SHARE_FEEDER(CLEAR: INTEGER): USAGE=QUERY, USERLIST=(twin), TIMEOUT=3 SEC.
pub type ShareFeeder = Port<(), i32, usage::Query>;
/// The feeder zone's ports: a chip robot sends its name (or, to the coordinator, the space
/// it will sweep) and waits until it may enter (or has left).
pub type ZonePort<Req = ZoneAsker> = Port<Req, (), usage::Receive, AnyUser, 2>;

/// LINE_DOWN: the world tells FEEDER_MONITOR that a line's process has died, and which run
/// of it comes next (see [`ZoneAsker`]). It stays in the world's process.
pub type LineDownPort = Port<(Line, u32), (), usage::Receive, AnyUser, 1>;

/// Where a chip robot finds a port of the feeder zone's keeper — the arbiter or the
/// coordinator: declared in this process, or imported from the process the keeper runs in.
#[derive(Clone)]
pub enum ZoneLink<Req: Send + 'static = ZoneAsker> {
    /// The port itself.
    Here(ZonePort<Req>),
    /// The port of another process, through its bridge.
    Imported(Imported<Req, ()>),
}

impl<Req: Send + 'static> fmt::Debug for ZoneLink<Req> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ZoneLink::Here(port) => f.debug_tuple("Here").field(port.name()).finish(),
            ZoneLink::Imported(port) => {
                f.debug_tuple("Imported").field(port.port().name()).finish()
            }
        }
    }
}

impl<Req: Send + 'static> ZoneLink<Req> {
    /// The end of the task `ctx`'s module to send on: to the port declared here, or
    /// imported from another process.
    pub fn user<S: Send + Sync + 'static>(
        &self,
        ctx: &Ctx<S>,
    ) -> Result<End<Req, (), usage::Send>, WireError> {
        match self {
            ZoneLink::Here(port) => ctx.user(port),
            ZoneLink::Imported(port) => ctx.user(port.port()),
        }
    }

    /// The owner's end: refused with the port's own error if the port was imported (its
    /// owner runs in another process).
    pub fn owner(&self) -> Result<End<Req, (), usage::Receive>, WireError> {
        match self {
            ZoneLink::Here(port) => port.owner(),
            ZoneLink::Imported(port) => port.port().owner(),
        }
    }

    /// The port in this process, to own and to declare; `None` if it was imported.
    pub fn here(&self) -> Option<&ZonePort<Req>> {
        match self {
            ZoneLink::Here(port) => Some(port),
            ZoneLink::Imported(_) => None,
        }
    }
}

/// The coordinator's reservation port: a chip robot sends the space its trajectory will
/// sweep and waits until that space is its own.
pub type ReservePort = ZonePort<Reservation>;

/// One line's ports.
#[derive(Debug, Clone)]
pub struct LinePorts {
    /// FREQUENCY, owned by GATE, filtered by BOUNDED_BUFFER.
    pub frequency: Frequency,
    /// LET_1_GO, owned by GATE.
    pub let_1_go: Let1Go,
    /// ASK_CHILD1, owned by LOAD_IT.
    pub ask_child1: AskChild1,
    /// ASK_CHILD2, owned by LOAD_IT.
    pub ask_child2: AskChild2,
    /// PALLET_IN_PLACE, owned by LOAD_CARD.
    pub pallet_in_place: PalletInPlace,
    /// CARD_IN_PLACE, owned by LOAD_CARD.
    pub card_in_place: CardInPlace,
    /// READY_TO_CHIP, owned by CHIP_IT.
    pub ready_to_chip: ReadyToChip,
    /// The feeder port this line's CHIP_IT owns.
    pub share_feeder: ShareFeeder,
}

/// Every port of the cell.
#[derive(Debug, Clone)]
pub struct CellPorts {
    /// Per line, A then B.
    pub lines: [LinePorts; 2],
    /// The arbiter's request port.
    pub zone_request: ZoneLink<ZoneAsker>,
    /// The arbiter's release port.
    pub zone_release: ZoneLink<ZoneAsker>,
    /// The arbiter's port where the world says a line's process died.
    pub line_down: LineDownPort,
    /// The coordinator's reservation port.
    pub zone_reserve: ZoneLink<Reservation>,
    /// The coordinator's port for freeing a reservation.
    pub zone_free: ZoneLink,
    /// The coordinator's port where the world says a line's process died.
    pub coordinator_down: LineDownPort,
}

fn spec(name: &str, owner: &str, clock: &SharedClock) -> PortSpec {
    PortSpec::new(name, owner).clock(clock.clone())
}

fn secs(seconds: u64) -> Duration {
    Duration::from_secs(seconds)
}

impl LinePorts {
    /// Declares `line`'s ports on `clock`.
    pub fn new(line: Line, clock: &SharedClock) -> Self {
        let n = LineNames::of(line);
        let twin = LineNames::of(line.other());
        Self {
            frequency: Frequency::new(
                spec(&n.frequency, &n.gate, clock)
                    .user_list([n.load_it.clone(), n.chip_it.clone()]),
                "BOUNDED_BUFFER",
            )
            .shown(),
            let_1_go: Let1Go::new(spec(&n.let_1_go, &n.gate, clock).owner_timeout(secs(2))).shown(),
            ask_child1: AskChild1::new(
                spec(&n.ask_child1, &n.load_it, clock)
                    .user_list([n.load_card.clone()])
                    .owner_timeout(secs(2)),
            )
            .shown(),
            ask_child2: AskChild2::new(
                spec(&n.ask_child2, &n.load_it, clock)
                    .user_list([n.screw_in_card.clone()])
                    .owner_timeout(secs(2)),
            )
            .shown(),
            pallet_in_place: PalletInPlace::new(
                spec(&n.pallet_in_place, &n.load_card, clock).owner_timeout(secs(30)),
            )
            .shown(),
            card_in_place: CardInPlace::new(
                spec(&n.card_in_place, &n.load_card, clock)
                    .user_list([n.screw_in_card.clone()])
                    .owner_timeout(secs(30)),
            )
            .shown(),
            ready_to_chip: ReadyToChip::new(
                spec(&n.ready_to_chip, &n.chip_it, clock).owner_timeout(secs(60)),
            )
            .shown(),
            share_feeder: ShareFeeder::new(
                spec(&n.share_feeder, &n.chip_it, clock)
                    .user_list([twin.chip_it.clone()])
                    .owner_timeout(secs(3)),
            )
            .shown(),
        }
    }
}

impl LinePorts {
    /// Makes this line's ports known to `cell`, for the wiring check.
    pub fn declare_to(&self, cell: &Cell) -> Result<(), WireError> {
        cell.declare(&self.frequency)?;
        cell.declare(&self.let_1_go)?;
        cell.declare(&self.ask_child1)?;
        cell.declare(&self.ask_child2)?;
        cell.declare(&self.pallet_in_place)?;
        cell.declare(&self.card_in_place)?;
        cell.declare(&self.ready_to_chip)?;
        cell.declare(&self.share_feeder)
    }
}

impl CellPorts {
    /// Declares every port on `clock`, none of them yet known to a cell.
    pub fn new(clock: &SharedClock) -> Self {
        Self {
            lines: [
                LinePorts::new(Line::A, clock),
                LinePorts::new(Line::B, clock),
            ],
            zone_request: ZoneLink::Here(
                ZonePort::new(spec(ZONE_REQUEST, FEEDER_MONITOR, clock)).shown(),
            ),
            zone_release: ZoneLink::Here(
                ZonePort::new(spec(ZONE_RELEASE, FEEDER_MONITOR, clock)).shown(),
            ),
            line_down: LineDownPort::new(spec(LINE_DOWN, FEEDER_MONITOR, clock)).shown(),
            zone_reserve: ZoneLink::Here(
                ReservePort::new(spec(ZONE_RESERVE, FEEDER_COORDINATOR, clock)).shown(),
            ),
            zone_free: ZoneLink::Here(
                ZonePort::new(spec(ZONE_FREE, FEEDER_COORDINATOR, clock)).shown(),
            ),
            coordinator_down: LineDownPort::new(spec(LINE_DOWN, FEEDER_COORDINATOR, clock)).shown(),
        }
    }

    /// Declares every port on `cell`'s clock, and makes each known to `cell` for the wiring
    /// check; the arbiter's or the coordinator's ports only under its policy.
    pub fn declare(cell: &Cell, policy: FeederPolicy) -> Result<Self, WireError> {
        let ports = Self::new(cell.clock());
        for line in &ports.lines {
            line.declare_to(cell)?;
        }
        match policy {
            FeederPolicy::Arbiter => {
                for link in [&ports.zone_request, &ports.zone_release] {
                    if let Some(port) = link.here() {
                        cell.declare(port)?;
                    }
                }
                cell.declare(&ports.line_down)?;
            }
            FeederPolicy::Coordinator => {
                if let Some(port) = ports.zone_reserve.here() {
                    cell.declare(port)?;
                }
                if let Some(port) = ports.zone_free.here() {
                    cell.declare(port)?;
                }
                cell.declare(&ports.coordinator_down)?;
            }
            FeederPolicy::Appendix => {}
        }
        Ok(ports)
    }
}
