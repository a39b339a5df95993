//! A port automaton run as a schema, on synchronous ports: the same declaration the
//! composition explores, behaving in a network.

use std::sync::{Arc, Mutex, PoisonError};

use imrs_ports::Name;
use imrs_ports::synchronous::{AnyPort, Input, Output};

use super::def::{PortAutomaton, Step, Value};
use crate::{Behavior, Cx, Flow, Ports, Schema, SchemaError};

/// A [`PortAutomaton`] as a schema: each pass of its behaviour is one step, a read or a
/// write on its synchronous ports, or STOP. The states it goes through are kept
/// ([`AutomatonSchema::visited`]), to set beside a run of the composition.
#[derive(Debug)]
pub struct AutomatonSchema {
    automaton: PortAutomaton,
    state: String,
    visited: Arc<Mutex<Vec<String>>>,
}

impl AutomatonSchema {
    /// The schema of `automaton`, in its start state.
    pub fn new(automaton: PortAutomaton) -> Self {
        let state = automaton.start().to_string();
        Self {
            visited: Arc::new(Mutex::new(vec![state.clone()])),
            automaton,
            state,
        }
    }

    /// The states it has gone through so far, its start first.
    pub fn visited(&self) -> Arc<Mutex<Vec<String>>> {
        Arc::clone(&self.visited)
    }
}

/// An automaton's ports: one synchronous input per port it reads, one output per port it
/// writes, named as the automaton names them.
#[derive(Debug)]
pub struct AutomatonPorts {
    inputs: Vec<(&'static str, Input<Value>)>,
    outputs: Vec<(&'static str, Output<Value>)>,
}

impl AutomatonPorts {
    fn of(automaton: &PortAutomaton, owner: &Name) -> Self {
        Self {
            inputs: automaton
                .inputs()
                .into_iter()
                .map(|port| (port, Input::new(port, owner.clone())))
                .collect(),
            outputs: automaton
                .outputs()
                .into_iter()
                .map(|port| (port, Output::new(port, owner.clone())))
                .collect(),
        }
    }

    /// The input `port`, if the automaton reads it.
    pub fn input(&self, port: &str) -> Option<&Input<Value>> {
        self.inputs.iter().find(|(p, _)| *p == port).map(|(_, i)| i)
    }

    /// The output `port`, if the automaton writes it.
    pub fn output(&self, port: &str) -> Option<&Output<Value>> {
        self.outputs
            .iter()
            .find(|(p, _)| *p == port)
            .map(|(_, o)| o)
    }
}

impl Ports for AutomatonPorts {
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)> {
        let inputs = self.inputs.iter().map(|(p, i)| (*p, i as &dyn AnyPort));
        let outputs = self.outputs.iter().map(|(p, o)| (*p, o as &dyn AnyPort));
        inputs.chain(outputs).collect()
    }
}

impl Schema for AutomatonSchema {
    const NAME: &'static str = "PortAutomaton";
    type Ports = AutomatonPorts;

    /// Each instance is named after its automaton: `Grip_1`, `Closejoint_2_3`.
    fn label(&self) -> Option<&str> {
        Some(self.automaton.name())
    }

    fn set_up(&mut self, cx: &Cx) -> Result<AutomatonPorts, SchemaError> {
        self.automaton
            .check()
            .map_err(|error| SchemaError::Failed {
                instance: cx.me().clone(),
                reason: error.to_string(),
            })?;
        Ok(AutomatonPorts::of(&self.automaton, cx.me()))
    }

    async fn behavior(&mut self, ports: &AutomatonPorts, cx: &Cx) -> Behavior {
        let failed = |reason: String| SchemaError::Failed {
            instance: cx.me().clone(),
            reason,
        };
        let step = self.automaton.step(&self.state).cloned();
        self.state = match step {
            Some(Step::Read { port, .. }) => {
                let input = ports.input(port).expect("a port read is declared");
                let value = input.read().await?;
                self.automaton
                    .after_read(&self.state, value)
                    .map_err(|error| failed(error.to_string()))?
            }
            Some(Step::Write { port, value, next }) => {
                let output = ports.output(port).expect("a port written is declared");
                output.write(value).await?;
                next
            }
            Some(Step::Stop) => return Ok(Flow::Stop),
            None => return Err(failed(format!("it has no state {}", self.state))),
        };
        self.visited
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(self.state.clone());
        Ok(Flow::Continue)
    }
}
