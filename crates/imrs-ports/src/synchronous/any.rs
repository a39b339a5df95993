//! Ends whose type is known only at run time: connections made by name, as a connection map
//! given at instantiation is.

use std::any::{Any, type_name};
use std::fmt;

use super::error::ConnectError;
use super::{Input, Output};
use crate::meta::Name;

/// Which way a port carries values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Read by its owner.
    Input,
    /// Written by its owner.
    Output,
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Input => "input",
            Self::Output => "output",
        })
    }
}

/// A synchronous port of any type.
pub trait AnyPort: Send + Sync + 'static {
    /// The port's name.
    fn port(&self) -> &Name;
    /// The instance that owns it.
    fn owner(&self) -> &Name;
    /// Input or output.
    fn direction(&self) -> Direction;
    /// The type of its values, as Rust names it.
    fn message_type(&self) -> &'static str;
    /// Closes the port.
    fn close(&self);
    /// The port as `Any`, to recover its type.
    fn as_any(&self) -> &dyn Any;
    /// Connects this output to `input` if it reads the same type; false otherwise.
    #[doc(hidden)]
    fn connect_to(&self, input: &dyn AnyPort) -> bool;
}

impl<T: Clone + Send + Sync + 'static> AnyPort for Input<T> {
    fn port(&self) -> &Name {
        Input::port(self)
    }
    fn owner(&self) -> &Name {
        Input::owner(self)
    }
    fn direction(&self) -> Direction {
        Direction::Input
    }
    fn message_type(&self) -> &'static str {
        type_name::<T>()
    }
    fn close(&self) {
        Input::close(self);
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn connect_to(&self, _: &dyn AnyPort) -> bool {
        false
    }
}

impl<T: Clone + Send + Sync + 'static> AnyPort for Output<T> {
    fn port(&self) -> &Name {
        Output::port(self)
    }
    fn owner(&self) -> &Name {
        Output::owner(self)
    }
    fn direction(&self) -> Direction {
        Direction::Output
    }
    fn message_type(&self) -> &'static str {
        type_name::<T>()
    }
    fn close(&self) {
        Output::close(self);
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn connect_to(&self, input: &dyn AnyPort) -> bool {
        match input.as_any().downcast_ref::<Input<T>>() {
            Some(input) => {
                self.connect(input);
                true
            }
            None => false,
        }
    }
}

/// `INSTANCE(PORT)`, as errors name an end.
pub(crate) fn end_name(port: &dyn AnyPort) -> String {
    format!("{}({})", port.owner(), port.port())
}

/// Connects `output` to `input`, checking at run time what [`connect`](super::connect)
/// checks at compile time: directions, and that both carry one type.
pub fn connect_any(output: &dyn AnyPort, input: &dyn AnyPort) -> Result<(), ConnectError> {
    for (end, expected) in [(output, Direction::Output), (input, Direction::Input)] {
        if end.direction() != expected {
            return Err(ConnectError::Direction {
                port: end_name(end),
                expected,
            });
        }
    }
    if output.connect_to(input) {
        Ok(())
    } else {
        Err(ConnectError::Types {
            output: end_name(output),
            output_type: output.message_type(),
            input: end_name(input),
            input_type: input.message_type(),
        })
    }
}
