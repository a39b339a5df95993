//! Names a test gives what it shares with other processes.

use std::time::{SystemTime, UNIX_EPOCH};

/// A name that no other run of the tests shares now, for `test`:
/// `t<process id>-<test>-<nanoseconds of the clock>`. Tests that run at once, in one
/// process or in several, never meet under it.
pub fn unique_name(test: &str) -> String {
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    format!("t{}-{test}-{nanos}", std::process::id())
}
