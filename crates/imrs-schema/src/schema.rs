//! The schema: the seed's unit of distributed computation.

use std::future::Future;

use crate::cx::Cx;
use crate::error::SchemaError;
use crate::ports::Ports;

/// What a pass of a behaviour says next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Run the behaviour again: it "cycles continuously until the instance is
    /// deinstantiated".
    Continue,
    /// `STOP`: the instance deinstantiates itself.
    Stop,
}

/// The result of one pass of a behaviour: a read or write that fails ends the instance
/// with its error (use `?`).
pub type Behavior = Result<Flow, SchemaError>;

/// Which of the seed's three constructs a schema is; it decides where its behaviour
/// instantiates and when the instance ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `[N (ip) (op) (v) (b)]`: ports, internal variables, a behaviour. Instances its
    /// behaviour makes are components of the assemblage it is in. It ends on `STOP`.
    Schema,
    /// `[N (ip) (op) (s) (ib) (p) (n)]`: components set up by [`Schema::set_up`], which
    /// returns the component ports that stand for the assemblage's own (`p`). It has no
    /// behaviour of its own, and ends when all its components have ended.
    Assemblage,
    /// `[N (ip) (op) (sl) (ml) (ib) (var) (b)]`: sensing and motor components set up by
    /// [`Schema::set_up`], and an r-schema: the behaviour, whose ports are the task-unit's.
    /// It ends when its r-schema stops, and its components with it.
    TaskUnit,
}

/// A schema: its name, ports, internal variables (the implementing type's fields, given
/// their initial values by constructing it) and behaviour.
///
/// ```
/// use imrs_schema::{Behavior, Cx, Declare, Flow, Schema, SchemaError, ports};
///
/// ports! {
///     /// `(Tin Pin) (Pout)`
///     pub struct TClosejointPorts { in tin: bool = "Tin", in pin: f32 = "Pin", out pout: f32 = "Pout" }
/// }
///
/// /// `[TClosejoint (Tin Pin) (Pout) (Del) (IF Tin=0 THEN Pout:=Pin+Del ELSE Pout:=Pin ENDIF)]`
/// struct TClosejoint { del: f32 }
///
/// impl Schema for TClosejoint {
///     const NAME: &'static str = "TClosejoint";
///     type Ports = TClosejointPorts;
///
///     fn set_up(&mut self, cx: &Cx) -> Result<Self::Ports, SchemaError> {
///         Ok(Declare::declare(cx.me()))
///     }
///
///     async fn behavior(&mut self, p: &Self::Ports, _: &Cx) -> Behavior {
///         let (touching, at) = (p.tin.read().await?, p.pin.read().await?);
///         p.pout.write(if touching { at } else { at + self.del }).await?;
///         Ok(Flow::Continue)
///     }
/// }
/// ```
pub trait Schema: Send + Sized + 'static {
    /// `N`: the schema's name. Instances are named `N_i`.
    const NAME: &'static str;
    /// Which construct this is.
    const KIND: Kind = Kind::Schema;
    /// Whether `FORALL` finds instances of this schema from inside any assemblage, not only
    /// the one they are components of (the seed's SEF instances are "local to all
    /// assemblages").
    const EVERYWHERE: bool = false;
    /// `(ip)` and `(op)`.
    type Ports: Ports;

    /// The name its instances go by, if not [`NAME`](Self::NAME): instances of a schema
    /// whose values are different things (a port automaton run as a schema) are named
    /// after what each is, `label_i`. They are still `NAME`'s for `FORALL`, and numbered
    /// among them.
    fn label(&self) -> Option<&str> {
        None
    }

    /// Makes the instance's ports, and for an assemblage or a task-unit instantiates and
    /// connects its components in `cx` (its own inside). A plain schema declares fresh
    /// ports: `Ok(Declare::declare(cx.me()))`.
    fn set_up(&mut self, cx: &Cx) -> Result<Self::Ports, SchemaError>;

    /// `(b)`: one pass of the behaviour. An assemblage has none: this is never called.
    fn behavior(&mut self, ports: &Self::Ports, cx: &Cx) -> impl Future<Output = Behavior> + Send {
        let _ = (ports, cx);
        async { Ok(Flow::Stop) }
    }
}
