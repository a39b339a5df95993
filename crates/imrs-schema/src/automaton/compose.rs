//! A network of port automata composed into one, and explored state by state.
//!
//! The composed automaton's state is every automaton's state. It moves when a reading
//! automaton and the writing automaton its input is connected to meet (a rendezvous, as the
//! synchronous ports have it: a write waits for a read, a read for a write), when an input
//! left to the environment reads any value of its domain, or when an output given to the
//! environment is written. An input connected to nothing, and an output read by nothing,
//! wait for ever, as an unconnected synchronous port does.

use std::collections::{BTreeMap, HashMap, VecDeque};

use super::def::{AutomatonError, PortAutomaton, Step, Value};

/// An automaton's port in a composition: the automaton's name and the port's.
pub type At<'a> = (&'a str, &'static str);

/// Port automata composed into one.
#[derive(Debug, Clone)]
pub struct Composition {
    automata: Vec<PortAutomaton>,
    /// Reader (automaton, input) → writer (automaton, output).
    writers: BTreeMap<(usize, &'static str), (usize, &'static str)>,
    /// Inputs the environment writes, with the values it may write.
    sources: BTreeMap<(usize, &'static str), Vec<Value>>,
    /// Outputs the environment reads.
    sinks: Vec<(usize, &'static str)>,
}

/// A reachable state where nothing can move and not every automaton has stopped: a global
/// deadlock. (Automata blocked for ever while others go on are not one; such a run shows
/// as one that does not end.)
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stuck {
    /// The moves from the start to it.
    pub path: Vec<String>,
    /// Each automaton's state there, by name.
    pub states: Vec<(String, String)>,
}

/// What an exhaustive exploration of a composition found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Exploration {
    /// Reachable states of the composed automaton.
    pub states: usize,
    /// A deadlock, if one is reachable: the first found, by the shortest path.
    pub deadlock: Option<Stuck>,
    /// Whether every run ends with every automaton stopped: no deadlock is reachable, and
    /// no run goes on for ever.
    pub always_ends: bool,
}

/// One run of a composition on given environment values: each automaton's states, in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Run {
    /// For each automaton, by name, the states it went through, its start first.
    pub visited: BTreeMap<String, Vec<String>>,
    /// Whether every automaton stopped.
    pub ended: bool,
}

type Global = Vec<String>;

/// One move of the composed automaton.
struct Move {
    label: String,
    next: Global,
    /// The automata that took a step.
    movers: Vec<usize>,
    /// The environment input read, if one was.
    from_environment: Option<(usize, &'static str)>,
}

impl Composition {
    /// The composition of `automata`, each checked, none connected yet.
    pub fn new(automata: impl IntoIterator<Item = PortAutomaton>) -> Result<Self, AutomatonError> {
        let automata: Vec<PortAutomaton> = automata.into_iter().collect();
        for (i, automaton) in automata.iter().enumerate() {
            automaton.check()?;
            if automata[..i].iter().any(|a| a.name() == automaton.name()) {
                return Err(AutomatonError::Duplicate(automaton.name().to_string()));
            }
        }
        Ok(Self {
            automata,
            writers: BTreeMap::new(),
            sources: BTreeMap::new(),
            sinks: Vec::new(),
        })
    }

    fn find(&self, (name, port): At<'_>, input: bool) -> Result<usize, AutomatonError> {
        let missing = || AutomatonError::NoPort {
            automaton: name.to_string(),
            port: port.to_string(),
        };
        let index = self
            .automata
            .iter()
            .position(|a| a.name() == name)
            .ok_or_else(missing)?;
        let ports = if input {
            self.automata[index].inputs()
        } else {
            self.automata[index].outputs()
        };
        ports.contains(&port).then_some(index).ok_or_else(missing)
    }

    fn taken(&self, reader: (usize, &'static str)) -> bool {
        self.writers.contains_key(&reader) || self.sources.contains_key(&reader)
    }

    fn not_one_to_one(&self, (index, port): (usize, &'static str)) -> AutomatonError {
        AutomatonError::NotOneToOne {
            automaton: self.automata[index].name().to_string(),
            port: port.to_string(),
        }
    }

    /// Connects output `from` to input `to`.
    pub fn connect(mut self, from: At<'_>, to: At<'_>) -> Result<Self, AutomatonError> {
        let writer = (self.find(from, false)?, from.1);
        let reader = (self.find(to, true)?, to.1);
        if self.taken(reader) {
            return Err(self.not_one_to_one(reader));
        }
        if self.writers.values().any(|w| *w == writer) || self.sinks.contains(&writer) {
            return Err(self.not_one_to_one(writer));
        }
        self.writers.insert(reader, writer);
        Ok(self)
    }

    /// The environment writes input `to`, any of `values` at any time.
    pub fn environment(
        mut self,
        to: At<'_>,
        values: impl IntoIterator<Item = Value>,
    ) -> Result<Self, AutomatonError> {
        let reader = (self.find(to, true)?, to.1);
        if self.taken(reader) {
            return Err(self.not_one_to_one(reader));
        }
        self.sources.insert(reader, values.into_iter().collect());
        Ok(self)
    }

    /// The environment reads output `from`, whenever it is written.
    pub fn sink(mut self, from: At<'_>) -> Result<Self, AutomatonError> {
        let writer = (self.find(from, false)?, from.1);
        if self.writers.values().any(|w| *w == writer) || self.sinks.contains(&writer) {
            return Err(self.not_one_to_one(writer));
        }
        self.sinks.push(writer);
        Ok(self)
    }

    fn start(&self) -> Global {
        self.automata
            .iter()
            .map(|a| a.start().to_string())
            .collect()
    }

    fn step<'s>(&'s self, global: &Global, index: usize) -> &'s Step {
        self.automata[index]
            .step(&global[index])
            .expect("states are checked as they are entered")
    }

    fn stopped(&self, global: &Global) -> bool {
        (0..self.automata.len()).all(|i| matches!(self.step(global, i), Step::Stop))
    }

    /// Every move from `global`. Environment inputs read each value of their domain, or,
    /// with `script`, the next value scripted (none once the script is spent).
    fn moves(
        &self,
        global: &Global,
        script: Option<&BTreeMap<(usize, &'static str), VecDeque<Value>>>,
    ) -> Result<Vec<Move>, AutomatonError> {
        let mut moves = Vec::new();
        for (index, automaton) in self.automata.iter().enumerate() {
            let name = automaton.name();
            match self.step(global, index) {
                Step::Read { port, .. } => {
                    let reader = (index, *port);
                    if let Some(domain) = self.sources.get(&reader) {
                        let values: Vec<Value> = match script {
                            Some(script) => script
                                .get(&reader)
                                .and_then(VecDeque::front)
                                .copied()
                                .into_iter()
                                .collect(),
                            None => domain.clone(),
                        };
                        for value in values {
                            let mut next = global.clone();
                            next[index] = automaton.after_read(&global[index], value)?;
                            moves.push(Move {
                                label: format!("{name} reads {value} on {port}"),
                                next,
                                movers: vec![index],
                                from_environment: Some(reader),
                            });
                        }
                    } else if let Some(&(w, out)) = self.writers.get(&reader)
                        && let Step::Write {
                            port: written,
                            value,
                            next: after,
                        } = self.step(global, w)
                        && *written == out
                    {
                        let mut next = global.clone();
                        next[index] = automaton.after_read(&global[index], *value)?;
                        next[w] = after.clone();
                        moves.push(Move {
                            label: format!(
                                "{} writes {value} on {out}, {name} reads it on {port}",
                                self.automata[w].name()
                            ),
                            next,
                            movers: vec![w, index],
                            from_environment: None,
                        });
                    }
                }
                Step::Write { port, value, next } if self.sinks.contains(&(index, *port)) => {
                    let mut after = global.clone();
                    after[index] = next.clone();
                    moves.push(Move {
                        label: format!("{name} writes {value} on {port}"),
                        next: after,
                        movers: vec![index],
                        from_environment: None,
                    });
                }
                Step::Write { .. } | Step::Stop => {}
            }
        }
        Ok(moves)
    }

    /// Explores every reachable state: can the composition deadlock, and does every run end?
    pub fn explore(&self) -> Result<Exploration, AutomatonError> {
        let start = self.start();
        let mut index: HashMap<Global, usize> = HashMap::from([(start.clone(), 0)]);
        let mut states: Vec<Global> = vec![start];
        let mut parent: Vec<Option<(usize, String)>> = vec![None];
        let mut edges: Vec<Vec<usize>> = Vec::new();
        let mut deadlock = None;
        let mut at = 0;
        while at < states.len() {
            let moves = self.moves(&states[at], None)?;
            if moves.is_empty() && !self.stopped(&states[at]) && deadlock.is_none() {
                deadlock = Some(at);
            }
            let mut out = Vec::with_capacity(moves.len());
            for Move { label, next, .. } in moves {
                let to = *index.entry(next.clone()).or_insert_with(|| {
                    states.push(next);
                    parent.push(Some((at, label)));
                    states.len() - 1
                });
                out.push(to);
            }
            edges.push(out);
            at += 1;
        }
        let always_ends = deadlock.is_none() && !has_cycle(&edges);
        let deadlock = deadlock.map(|stuck| {
            let mut path = Vec::new();
            let mut at = stuck;
            while let Some((from, label)) = &parent[at] {
                path.push(label.clone());
                at = *from;
            }
            path.reverse();
            Stuck {
                path,
                states: self
                    .automata
                    .iter()
                    .zip(&states[stuck])
                    .map(|(a, s)| (a.name().to_string(), s.clone()))
                    .collect(),
            }
        });
        Ok(Exploration {
            states: states.len(),
            deadlock,
            always_ends,
        })
    }

    /// One run, the environment writing each input the values `script` gives it in turn
    /// (and nothing once they are spent), until nothing can move, or until the run comes
    /// back to a state it was in with the same values left to write: it would go round for
    /// ever, and is reported as not ended.
    pub fn run(&self, script: &[(At<'_>, Vec<Value>)]) -> Result<Run, AutomatonError> {
        let mut queues: BTreeMap<(usize, &'static str), VecDeque<Value>> = BTreeMap::new();
        for (at, values) in script {
            let reader = (self.find(*at, true)?, at.1);
            queues.insert(reader, values.iter().copied().collect());
        }
        let mut global = self.start();
        let mut visited: BTreeMap<String, Vec<String>> = self
            .automata
            .iter()
            .map(|a| (a.name().to_string(), vec![a.start().to_string()]))
            .collect();
        let mut seen: std::collections::HashSet<(Global, Vec<usize>)> = Default::default();
        loop {
            let left: Vec<usize> = queues.values().map(VecDeque::len).collect();
            if !seen.insert((global.clone(), left)) {
                break;
            }
            let moves = self.moves(&global, Some(&queues))?;
            // Each automaton's own states depend only on the values it reads, so which
            // move goes first does not change them: take the first.
            let Some(taken) = moves.into_iter().next() else {
                break;
            };
            for &i in &taken.movers {
                visited
                    .get_mut(self.automata[i].name())
                    .expect("every automaton is listed")
                    .push(taken.next[i].clone());
            }
            if let Some(reader) = taken.from_environment
                && let Some(queue) = queues.get_mut(&reader)
            {
                queue.pop_front();
            }
            global = taken.next;
        }
        Ok(Run {
            ended: self.stopped(&global),
            visited,
        })
    }
}

/// Whether the graph of `edges` (state → successors) has a cycle, self-loops included.
fn has_cycle(edges: &[Vec<usize>]) -> bool {
    // 0: not seen, 1: on the current path, 2: done.
    let mut mark = vec![0u8; edges.len()];
    for root in 0..edges.len() {
        if mark[root] != 0 {
            continue;
        }
        let mut stack = vec![(root, 0usize)];
        mark[root] = 1;
        while let Some((node, next)) = stack.pop() {
            if let Some(&to) = edges[node].get(next) {
                stack.push((node, next + 1));
                match mark[to] {
                    1 => return true,
                    0 => {
                        mark[to] = 1;
                        stack.push((to, 0));
                    }
                    _ => {}
                }
            } else {
                mark[node] = 2;
            }
        }
    }
    false
}
