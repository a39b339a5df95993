// A synchronous output connected to an input of another type: refused by the compiler.
use imrs_ports::synchronous::{Input, Output, connect};

fn main() {
    let pout = Output::<f32>::new("Pout", "Closejoint_1");
    let tin = Input::<bool>::new("Tin", "Closejoint_1");
    connect(&pout, &tin);
}
