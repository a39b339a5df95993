use imrs_ports::{Port, PortSpec, usage};

async fn load_it() {
    // FREQUENCY(TASK_NUM:INTEGER; TIME_FOR_ONE:REAL): not a string.
    let port = Port::<(i32, f64), (), usage::Receive>::new(PortSpec::new("FREQUENCY", "GATE"));
    let mut load_it = port.user_named("LOAD_IT").unwrap();
    let _ = load_it.send("twenty seconds").await;
}

fn main() {
    drop(load_it());
}
