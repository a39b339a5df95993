//! The Appendix's names, for the first line and its twin.
//!
//! Line A's modules and ports have the Appendix's names. Line B's modules carry a `2`, as
//! the Appendix names CHIP_IT's twin CHIP_IT2, and its ports a `_2`. The two feeder ports
//! keep the Appendix's names: SHARE_FEEDER (CHIP_IT's) and SHARE_FEEDER1 (CHIP_IT2's).

use imrs_sim::Line;

/// The names of one line's modules and ports.
#[derive(Debug, Clone)]
pub struct LineNames {
    /// GATE.
    pub gate: String,
    /// LOAD_IT.
    pub load_it: String,
    /// LOAD_CARD.
    pub load_card: String,
    /// SCREW_IN_CARD.
    pub screw_in_card: String,
    /// CHIP_IT.
    pub chip_it: String,
    /// FREQUENCY.
    pub frequency: String,
    /// LET_1_GO.
    pub let_1_go: String,
    /// ASK_CHILD1.
    pub ask_child1: String,
    /// ASK_CHILD2.
    pub ask_child2: String,
    /// PALLET_IN_PLACE.
    pub pallet_in_place: String,
    /// CARD_IN_PLACE.
    pub card_in_place: String,
    /// READY_TO_CHIP.
    pub ready_to_chip: String,
    /// The feeder port this line's CHIP_IT owns (it queries the twin through it).
    pub share_feeder: String,
}

impl LineNames {
    /// The names on `line`.
    pub fn of(line: Line) -> Self {
        let (module, port) = match line {
            Line::A => ("", ""),
            Line::B => ("2", "_2"),
        };
        let module = |name: &str| format!("{name}{module}");
        let port = |name: &str| format!("{name}{port}");
        Self {
            gate: module("GATE"),
            load_it: module("LOAD_IT"),
            load_card: module("LOAD_CARD"),
            screw_in_card: module("SCREW_IN_CARD"),
            chip_it: module("CHIP_IT"),
            frequency: port("FREQUENCY"),
            let_1_go: port("LET_1_GO"),
            ask_child1: port("ASK_CHILD1"),
            ask_child2: port("ASK_CHILD2"),
            pallet_in_place: port("PALLET_IN_PLACE"),
            card_in_place: port("CARD_IN_PLACE"),
            ready_to_chip: port("READY_TO_CHIP"),
            share_feeder: match line {
                Line::A => "SHARE_FEEDER".into(),
                Line::B => "SHARE_FEEDER1".into(),
            },
        }
    }
}

/// The arbiter of the shared feeders (the `--feeder arbiter` policy).
pub const FEEDER_MONITOR: &str = "FEEDER_MONITOR";
/// The arbiter's port for asking for the zone.
pub const ZONE_REQUEST: &str = "ZONE_REQUEST";
/// The arbiter's port for handing the zone back.
pub const ZONE_RELEASE: &str = "ZONE_RELEASE";
/// The arbiter's port where the world says a line's process has died.
pub const LINE_DOWN: &str = "LINE_DOWN";
/// Who says it: the world's supervision of the lines' processes.
pub const LINE_SUPERVISOR: &str = "LINE_SUPERVISOR";

/// The coordinator of the feeder zone (the `--feeder coordinator` policy).
pub const FEEDER_COORDINATOR: &str = "FEEDER_COORDINATOR";
/// The coordinator's port for reserving the space a trajectory sweeps.
pub const ZONE_RESERVE: &str = "ZONE_RESERVE";
/// The coordinator's port for freeing it.
pub const ZONE_FREE: &str = "ZONE_FREE";
