//! The feeder policies: how the two chip robots share the feeder zone. Apart from the chip
//! workcell, since the cell's ports, its runs and its report are each made under one.

/// How the two chip robots share the feeder zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FeederPolicy {
    /// The Appendix's scheme: query the twin's CRIT_SECTION, as CHIP_IT's order allows, with
    /// asymmetric timeout handlers to break the deadlock it admits (note 6).
    Appendix,
    /// A monitor task that hands the zone to one robot at a time.
    Arbiter,
    /// A coordinator (Jiménez et al. 1992) that reserves for each robot the space its trajectory will
    /// sweep, and lets both robots into the zone where their trajectories do not meet.
    Coordinator,
}

impl FeederPolicy {
    /// Its name, as `--feeder` takes it and the report prints it.
    pub fn name(self) -> &'static str {
        match self {
            FeederPolicy::Appendix => "appendix",
            FeederPolicy::Arbiter => "arbiter",
            FeederPolicy::Coordinator => "coordinator",
        }
    }
}
