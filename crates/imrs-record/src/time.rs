//! The cell's clock in the recording: an instant of the clock is nanoseconds from its start
//! (the cell's instants and a world's scene and facts all count from it).
//!
//! On virtual time the recording starts at the Unix epoch (Foxglove shows 1970-01-01): the
//! cell's own clock, so that two runs of the same seed give the same timestamps.

use std::time::Duration;

use foxglove::messages::Timestamp;

/// Nanoseconds since the clock's start, for `since` since it.
pub(crate) fn nanos(since: Duration) -> u64 {
    u64::try_from(since.as_nanos()).unwrap_or(u64::MAX)
}

/// A Foxglove timestamp for `since` the clock's start.
pub(crate) fn stamp(since: Duration) -> Timestamp {
    Timestamp::new(
        u32::try_from(since.as_secs()).unwrap_or(u32::MAX),
        since.subsec_nanos(),
    )
}
