use imrs_core::prelude::*;

// A response handler is made from the port it answers: one made from a port of another
// message type cannot answer this one's queries.
fn main() {
    let (cell, _clock) = Cell::virtual_clock();
    let status: Port<(), u32, usage::Response> =
        cell.port(PortSpec::new("STATUS", "PALLETIZER")).unwrap();
    let placed: Port<u8, u8, usage::Response> =
        cell.port(PortSpec::new("PLACED", "PALLETIZER")).unwrap();
    let ask = status.handler("ASK");
    let _ = ModuleSpec::new("PALLETIZER", 0u32)
        .order([ask.name(), "PALLETIZER".into()])
        .respond(&placed.handler("ASK"), |count: &u32, ()| *count);
}
