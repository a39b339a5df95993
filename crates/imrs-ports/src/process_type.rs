//! Process types (Shin 1985, section 2 and 4.2): the coupling of the subprocesses a port links.

/// The process class a port serves. It picks the implementation of the wait: a
/// [`Tight`](ProcessType::Tight) port spins briefly before parking, because a
/// tightly-coupled parent and child talk so often that a context switch costs more than a
/// short busy wait (Roberts et al., cited in Shin 1985, §4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ProcessType {
    /// Independent process.
    #[default]
    Indep,
    /// Loosely-coupled process.
    Loose,
    /// Tightly-coupled process: vertical control, frequent calls.
    Tight,
    /// Serialized motion process.
    Serial,
    /// Work-coupled process.
    Work,
}

impl ProcessType {
    /// How many times a wait on this port checks again before it parks.
    pub(crate) const fn spins(self) -> u32 {
        match self {
            ProcessType::Tight => 2_000,
            _ => 0,
        }
    }
}
