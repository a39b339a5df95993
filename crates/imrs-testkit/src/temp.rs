//! Files a test writes.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};

/// A path in the system's temporary directory, new at every call, ending in `name`:
/// `<prefix>-<process id>-<count>-<name>`, so that tests that run at once never share a
/// file. Nothing is made there.
pub fn temp_path(prefix: &str, name: &str) -> PathBuf {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("{prefix}-{}-{n}-{name}", std::process::id()))
}
