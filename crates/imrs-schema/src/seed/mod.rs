//! The four test examples of Lyons & Arbib 1985, §5, written in this crate's API, on the simulated
//! hand. The examples `guarded_move`, `reach`, `object_search` and `virtual_fingers` run
//! them; the tests check their physical outcome in rapier.
//!
//! | seed | here |
//! |---|---|
//! | `TClosejoint`, the r-schema of the guarded move | [`TClosejoint`] |
//! | the `Closejoint_i` task-unit (Figure 3) | [`Closejoint`] |
//! | `[Grip () () (Closejoint) (FOR i = 1…n DO Closejoint(i,10) ENDFOR) () ()]` | [`Grip`] |
//! | the guarded move with port arrays, "any number of joints based on one sensor, or one joint on any number of sensors" | [`GuardedMove`] |
//! | `RObject`, `Reach` (Figure 4) | [`RObject`], [`Reach`] |
//! | `Objtest`, `Object?` (Figure 5) | [`Objtest`], [`ObjectQ`] |
//! | the second precondition: `Object?` creates the tests and dies, the matching `Objtest` creates the task-unit | [`ObjectQOnce`], [`ObjtestTrigger`] |
//! | `VF_k`, `N = [T_i - F_i]`, `FORALL VF_k_i DO N(i) ENDFOR` | [`Vf`], [`Closefinger`], [`Grasp`] |
//! | Grip and its `Closejoint_i` as port automata (§4), and a synchronized variant | [`grip_automata`], [`synchronized_grip_automata`] |

mod grip;
mod grip_automata;
mod guarded;
mod object;
mod reach;
mod vf;

pub use grip::{Closejoint, Grip, TClosejoint, TClosejointPorts};
pub use grip_automata::{
    MAX_JOINTS, grip_automata, grip_done_port, grip_parts, synchronized_grip_automata,
};
pub use guarded::{GuardedMove, GuardedMovePorts};
pub use object::{
    Desired, Features, Judge, ObjectQ, ObjectQOnce, ObjectQPorts, Objtest, ObjtestPorts,
    ObjtestTrigger, Starter,
};
pub use reach::{RObject, RObjectPorts, Reach, ReachPorts};
pub use vf::{Closefinger, ClosefingerPorts, Grasp, Vf};
