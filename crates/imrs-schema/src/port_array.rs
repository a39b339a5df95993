//! Port arrays (Lyons & Arbib 1985, (5)): ports of one kind, subscripted `NAME_1 … NAME_n`,
//! declared together when an instance is set up, so that one schema serves any number of
//! sensors or limbs.

use std::collections::HashSet;
use std::sync::{Mutex, OnceLock, PoisonError};

use imrs_ports::Name;
use imrs_ports::synchronous::{AnyPort, Input, Output};

/// `NAME_i`, kept for the life of the process. Port names are given by the program, not
/// read from a peer, so there are only as many as the program's arrays have subscripts.
fn subscripted(name: &str, i: usize) -> &'static str {
    static NAMES: OnceLock<Mutex<HashSet<&'static str>>> = OnceLock::new();
    let full = format!("{name}_{i}");
    let mut names = NAMES
        .get_or_init(Mutex::default)
        .lock()
        .unwrap_or_else(PoisonError::into_inner);
    if let Some(&known) = names.get(full.as_str()) {
        return known;
    }
    let leaked: &'static str = Box::leak(full.into_boxed_str());
    names.insert(leaked);
    leaked
}

/// A port array: `NAME_1 … NAME_n`, each a port of its own, indexed from 1 as the seed
/// subscripts them.
///
/// ```
/// use imrs_schema::{Input, Name, PortArray};
///
/// let tin: PortArray<Input<bool>> = PortArray::inputs("Tin", 3, &Name::from("Grasp_1"));
/// assert_eq!(tin.len(), 3);
/// assert_eq!(tin.names(), ["Tin_1", "Tin_2", "Tin_3"]);
/// assert!(tin.get(0).is_none() && tin.get(3).is_some() && tin.get(4).is_none());
/// ```
#[derive(Debug, Clone)]
pub struct PortArray<P> {
    ports: Vec<(&'static str, P)>,
}

impl<T: Clone + Send + 'static> PortArray<Input<T>> {
    /// Inputs `name_1 … name_n` of the instance `owner`.
    pub fn inputs(name: &str, n: usize, owner: &Name) -> Self {
        Self::of(name, n, |port| Input::new(port, owner.clone()))
    }
}

impl<T: Clone + Send + 'static> PortArray<Output<T>> {
    /// Outputs `name_1 … name_n` of the instance `owner`.
    pub fn outputs(name: &str, n: usize, owner: &Name) -> Self {
        Self::of(name, n, |port| Output::new(port, owner.clone()))
    }
}

impl<P> PortArray<P> {
    fn of(name: &str, n: usize, make: impl Fn(&'static str) -> P) -> Self {
        Self {
            ports: (1..=n)
                .map(|i| {
                    let port = subscripted(name, i);
                    (port, make(port))
                })
                .collect(),
        }
    }

    /// How many ports.
    pub fn len(&self) -> usize {
        self.ports.len()
    }

    /// Whether it has none.
    pub fn is_empty(&self) -> bool {
        self.ports.is_empty()
    }

    /// The port subscripted `i` (from 1), if there is one.
    pub fn get(&self, i: usize) -> Option<&P> {
        self.ports.get(i.checked_sub(1)?).map(|(_, port)| port)
    }

    /// Every port, by subscript.
    pub fn iter(&self) -> impl Iterator<Item = &P> {
        self.ports.iter().map(|(_, port)| port)
    }

    /// The ports' names, by subscript.
    pub fn names(&self) -> Vec<&'static str> {
        self.ports.iter().map(|(name, _)| *name).collect()
    }
}

impl<P: AnyPort> PortArray<P> {
    /// Every port by its name, for a schema's [`Ports::list`](crate::Ports::list).
    pub fn list(&self) -> impl Iterator<Item = (&'static str, &dyn AnyPort)> {
        self.ports
            .iter()
            .map(|(name, port)| (*name, port as &dyn AnyPort))
    }
}
