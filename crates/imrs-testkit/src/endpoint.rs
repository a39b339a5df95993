//! Endpoints for hosts that a test starts.

use std::net::TcpListener;

/// A TCP endpoint on loopback that nothing listens on now, as zenoh writes it:
/// `tcp/127.0.0.1:<port>`.
///
/// # Panics
///
/// If loopback has no free port.
pub fn free_endpoint() -> String {
    let listener = TcpListener::bind("127.0.0.1:0").expect("a free port on loopback");
    let port = listener.local_addr().expect("its address").port();
    format!("tcp/127.0.0.1:{port}")
}
