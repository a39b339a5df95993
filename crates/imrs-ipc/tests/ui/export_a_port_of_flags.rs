use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_ipc::{Remote, ZeroCopySend, export};

// Self-contained and ZeroCopySend, but a peer could write 2 into the bool: not every bit
// pattern is a value, so reading it in place would be undefined behaviour.
#[derive(Debug, Clone, Copy, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("ui::Gripper")]
struct Gripper {
    closed: bool,
}

fn main() {
    let port: Port<Gripper, Gripper, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("GRIPPER", "OWNER"));
    let _ = export(&Remote::new("cell").unwrap(), &port);
}
