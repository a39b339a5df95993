use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_ipc::{Remote, export};

fn main() {
    // A String owns heap memory another process cannot read.
    let port: Port<String, String, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("NAMES", "OWNER"));
    let _ = export(&Remote::new("cell").unwrap(), &port);
}
