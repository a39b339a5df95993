//! The helpers the workspace's tests share, in one place instead of a copy in each test:
//!
//! - [`python_with`]: Python 3 with a module importable, installed with pip where missing;
//! - [`free_endpoint`]: a TCP endpoint on loopback that nothing listens on;
//! - [`example_binary`]: an example of the package under test, built beside the test;
//! - [`temp_path`]: a path in the temporary directory that no other test shares;
//! - [`unique_name`]: a name that no other run of the tests shares now;
//! - [`poll_once`]: one poll of a future, with a waker that does nothing.
//!
//! A dev-dependency only: nothing outside the tests links it. It uses the standard library
//! alone.

mod endpoint;
mod example;
mod name;
mod poll;
mod python;
mod temp;

pub use endpoint::free_endpoint;
pub use example::example_binary;
pub use name::unique_name;
pub use poll::poll_once;
pub use python::python_with;
pub use temp::temp_path;
