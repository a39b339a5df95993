//! The cell's clock in the recording: an instant of the clock is nanoseconds from its start.
//!
//! On virtual time the recording starts at the Unix epoch (Foxglove shows 1970-01-01): the
//! cell's own clock, so that two runs of the same seed give the same timestamps.

use foxglove::messages::Timestamp;
use imrs_core::imrs_ports::Instant;

/// Nanoseconds since the clock's start.
pub(crate) fn nanos(at: Instant) -> u64 {
    u64::try_from(at.since_start().as_nanos()).unwrap_or(u64::MAX)
}

/// A Foxglove timestamp for `at`.
pub(crate) fn stamp(at: Instant) -> Timestamp {
    let since = at.since_start();
    Timestamp::new(
        u32::try_from(since.as_secs()).unwrap_or(u32::MAX),
        since.subsec_nanos(),
    )
}
