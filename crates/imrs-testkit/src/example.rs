//! The examples of the package under test, as programs a test starts.

use std::path::PathBuf;

/// The example `name` of the package whose test runs, as `cargo test` builds it beside the
/// test: `examples/<name>` in the profile's directory, the one above the test's `deps/`.
///
/// # Panics
///
/// If the test's own path is unknown, or has no directory two levels up.
pub fn example_binary(name: &str) -> PathBuf {
    let test = std::env::current_exe().unwrap();
    let profile_dir = test.parent().and_then(|deps| deps.parent()).unwrap();
    profile_dir.join("examples").join(name)
}
