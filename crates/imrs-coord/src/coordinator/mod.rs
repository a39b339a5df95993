//! The zone coordinator as a module (Jiménez et al. 1992, centralized loose coordination), speaking
//! the seed's message set over typed ports.
//!
//! | seed | port | from → to |
//! |---|---|---|
//! | request to move in a shared zone; position (stopped inside); zone release; trajectory end | `TO_COORDINATOR`, a [`Message`], answered [`Answer::Grant`](crate::zones::Answer::Grant) or [`Answer::Sleep`](crate::zones::Answer::Sleep) | robot → coordinator |
//! | position information (where its links are); a trajectory's next points to check against the other robots; an alternative trajectory round the robots in the way | `SPACE`, a [`Geometry`], answered with what the coordinator [`Seen`] | robot → coordinator |
//! | alarm | `ALARM` (priority 1: served before everything else) | robot → coordinator |
//! | wake up (and back off, to resolve a deadlock) | `WAKE_<ROBOT>`, a [`Wake`] | coordinator → robot |
//! | alarm: an emergency stop reaches every robot | `EMERGENCY`, a `sendall` | coordinator → every robot |
//!
//! After every sleep it looks for deadlocks among the robots asleep, over exclusive zones,
//! tools and rights to move in shared zones; each victim is told to back off. A way it
//! finds blocked by a robot asleep at a border that waits for what the blocked robot holds
//! is a deadlock too, of space and zones, once the blocked robot says it waits
//! ([`RobotLink::wait_on`]): the sleeper is told to back off. A robot's way is checked
//! against the other robots where *they said* they were
//! ([`Positions`](crate::zones::Positions)): the coordinator knows no more of the cell than
//! its messages told it.
//!
//! The message set is in `messages`, the ports that carry it in `ports`; a robot's ends of
//! them in `robot`, and the module that serves them in `serving`.

mod messages;
mod ports;
mod robot;
mod serving;

pub use messages::{Geometry, Message, Seen, Wake};
pub use ports::{CoordinatorPorts, MAX_ROBOTS};
pub use robot::{Refused, RobotLink};
pub use serving::{ALTERNATIVE_REACH, CoordinatorLog, coordinator};
