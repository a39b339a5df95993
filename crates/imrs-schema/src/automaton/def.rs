//! One port automaton: its states, its ports, what it does in each state.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

/// What travels on an automaton's ports.
pub type Value = i64;

/// The transition map of a reading state: the next state for the value read.
pub type Transition = Arc<dyn Fn(Value) -> String + Send + Sync>;

/// What an automaton does in one state: the seed's port automaton, each state
/// communicating on one port as a schema's behaviour does, one read or write at a time.
#[derive(Clone)]
pub enum Step {
    /// Reads `port`; the transition map gives the next state for the value read.
    Read {
        /// The input port.
        port: &'static str,
        /// The next state, by value.
        next: Transition,
    },
    /// Writes `value` on `port` (the output map), then goes to `next`.
    Write {
        /// The output port.
        port: &'static str,
        /// What it writes.
        value: Value,
        /// The state after the write.
        next: String,
    },
    /// STOP: the automaton has ended.
    Stop,
}

impl fmt::Debug for Step {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read { port, .. } => write!(f, "read {port}"),
            Self::Write { port, value, next } => write!(f, "write {value} on {port}, then {next}"),
            Self::Stop => f.write_str("stop"),
        }
    }
}

/// A port automaton (Lyons & Arbib 1985, §4): states, input and output ports, a transition
/// map and an output map, and a start state. Declared state by state, then checked by
/// [`PortAutomaton::check`] (the composition checks each of its automata).
///
/// ```
/// use imrs_schema::automaton::PortAutomaton;
///
/// // Reads its tactile input until it touches, then says it is done, and stops.
/// let finger = PortAutomaton::new("Closefinger_1", "feel")
///     .read("feel", "Tin", |touching| if touching != 0 { "done" } else { "feel" })
///     .write("done", "Done", 1, "stop")
///     .stop("stop");
/// assert!(finger.check().is_ok());
/// assert_eq!(finger.inputs(), ["Tin"]);
/// assert_eq!(finger.outputs(), ["Done"]);
/// ```
#[derive(Debug, Clone)]
pub struct PortAutomaton {
    name: String,
    start: String,
    states: BTreeMap<String, Step>,
}

/// What is wrong with an automaton, or a composition of them, named.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AutomatonError {
    /// A state refers to a state the automaton does not have.
    NoState {
        /// The automaton.
        automaton: String,
        /// The state named.
        state: String,
    },
    /// One port is read in one state and written in another.
    BothWays {
        /// The automaton.
        automaton: String,
        /// The port.
        port: String,
    },
    /// A connection names an automaton or a port that is not there.
    NoPort {
        /// The automaton.
        automaton: String,
        /// The port.
        port: String,
    },
    /// Two automata of one name in a composition.
    Duplicate(String),
    /// A name that cannot name an instance: empty, or with a `/` (which parts an
    /// assemblage's path from its components').
    BadName(String),
    /// An input connected to more than one output, or an output to more than one input:
    /// the composition models one-to-one connections only.
    NotOneToOne {
        /// The automaton.
        automaton: String,
        /// The port.
        port: String,
    },
}

impl fmt::Display for AutomatonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoState { automaton, state } => {
                write!(
                    f,
                    "automaton {automaton} goes to state {state}, which it does not have"
                )
            }
            Self::BothWays { automaton, port } => {
                write!(f, "automaton {automaton} both reads and writes port {port}")
            }
            Self::BadName(name) => write!(
                f,
                "an automaton cannot be named {name:?}: a name is not empty and has no '/'"
            ),
            Self::NoPort { automaton, port } => {
                write!(
                    f,
                    "no port {port} on an automaton {automaton} of this composition"
                )
            }
            Self::Duplicate(name) => write!(f, "two automata named {name}"),
            Self::NotOneToOne { automaton, port } => write!(
                f,
                "port {port} of {automaton} has two connections; the composition models one each"
            ),
        }
    }
}

impl std::error::Error for AutomatonError {}

impl PortAutomaton {
    /// An automaton named `name` that starts in state `start`.
    pub fn new(name: impl Into<String>, start: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            start: start.into(),
            states: BTreeMap::new(),
        }
    }

    /// In `state` it reads `port`, and goes to the state `next` gives for the value.
    pub fn read<S: Into<String>>(
        mut self,
        state: impl Into<String>,
        port: &'static str,
        next: impl Fn(Value) -> S + Send + Sync + 'static,
    ) -> Self {
        let next: Transition = Arc::new(move |value| next(value).into());
        self.states.insert(state.into(), Step::Read { port, next });
        self
    }

    /// In `state` it writes `value` on `port`, then goes to `next`.
    pub fn write(
        mut self,
        state: impl Into<String>,
        port: &'static str,
        value: Value,
        next: impl Into<String>,
    ) -> Self {
        let next = next.into();
        self.states
            .insert(state.into(), Step::Write { port, value, next });
        self
    }

    /// `state` is final: the automaton stops there.
    pub fn stop(mut self, state: impl Into<String>) -> Self {
        self.states.insert(state.into(), Step::Stop);
        self
    }

    /// Its name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its start state.
    pub fn start(&self) -> &str {
        &self.start
    }

    /// What it does in `state`, if it has that state.
    pub fn step(&self, state: &str) -> Option<&Step> {
        self.states.get(state)
    }

    /// The ports it reads, each once, in name order.
    pub fn inputs(&self) -> Vec<&'static str> {
        self.ports(true)
    }

    /// The ports it writes, each once, in name order.
    pub fn outputs(&self) -> Vec<&'static str> {
        self.ports(false)
    }

    fn ports(&self, reading: bool) -> Vec<&'static str> {
        let mut ports: Vec<&'static str> = self
            .states
            .values()
            .filter_map(|step| match step {
                Step::Read { port, .. } if reading => Some(*port),
                Step::Write { port, .. } if !reading => Some(*port),
                _ => None,
            })
            .collect();
        ports.sort_unstable();
        ports.dedup();
        ports
    }

    /// Checks that its start state and every written state's next state exist, and that no
    /// port is both read and written. A reading state's transitions are checked as they are
    /// taken.
    pub fn check(&self) -> Result<(), AutomatonError> {
        if self.name.is_empty() || self.name.contains('/') {
            return Err(AutomatonError::BadName(self.name.clone()));
        }
        let no_state = |state: &str| AutomatonError::NoState {
            automaton: self.name.clone(),
            state: state.to_string(),
        };
        if !self.states.contains_key(&self.start) {
            return Err(no_state(&self.start));
        }
        for step in self.states.values() {
            if let Step::Write { next, .. } = step
                && !self.states.contains_key(next)
            {
                return Err(no_state(next));
            }
        }
        let inputs = self.inputs();
        if let Some(port) = self.outputs().into_iter().find(|p| inputs.contains(p)) {
            return Err(AutomatonError::BothWays {
                automaton: self.name.clone(),
                port: port.to_string(),
            });
        }
        Ok(())
    }

    /// The state after reading `value` in the reading state `state`, checked.
    pub(crate) fn after_read(&self, state: &str, value: Value) -> Result<String, AutomatonError> {
        let Some(Step::Read { next, .. }) = self.states.get(state) else {
            return Err(AutomatonError::NoState {
                automaton: self.name.clone(),
                state: state.to_string(),
            });
        };
        let next = next(value);
        if self.states.contains_key(&next) {
            Ok(next)
        } else {
            Err(AutomatonError::NoState {
                automaton: self.name.clone(),
                state: next,
            })
        }
    }
}
