use imrs_ports::{Port, PortSpec, usage};

fn main() {
    // ASK_CHILD2 is a QUERY port: its user answers with a response handler, so a plain
    // user end would leave LOAD_IT's queries with nobody to run them.
    let port = Port::<(), i32, usage::Query>::new(PortSpec::new("ASK_CHILD2", "LOAD_IT"));
    let _ = port.user_named("SCREW_IN_CARD");
}
