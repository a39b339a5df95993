//! What names a module in a peer host's query: a request's or a connection's key, whose last
//! chunk is the asking module, and a delivery's attachment, the owner's name. Each is read
//! as the ports read it, then claimed on a port with a user list, as the owner's host does:
//! a name that would change a key expression is refused; one off the list is refused and
//! never kept.

#![no_main]

use imrs_ports::{AnyUser, Name, Port, PortSpec, usage};
use imrs_zenoh::fuzzing::{module_in, sender};
use libfuzzer_sys::fuzz_target;

fn claimed(name: &str) {
    assert!(!name.is_empty() && !name.contains(['/', '*', '$', '?', '#']));
    let port: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "OWNER").user_list(["ROBOT_1"]));
    match port.claim(name) {
        Ok(_) => assert_eq!(name, "ROBOT_1"),
        Err(refused) => {
            assert!(refused.to_string().contains("DOUBLE"), "{refused}");
            if !["DOUBLE", "OWNER", "ROBOT_1"].contains(&name) {
                assert_eq!(Name::known(name), None, "{name:?} was kept");
            }
        }
    }
}

fuzz_target!(|bytes: &[u8]| {
    if let Ok(name) = sender(bytes) {
        assert_eq!(name.as_bytes(), bytes);
        claimed(&name);
    }
    if let Ok(key) = std::str::from_utf8(bytes)
        && let Ok(name) = module_in(key)
    {
        assert!(key.ends_with(name));
        claimed(name);
    }
});
