//! Headers another process wrote into shared memory beside a request or a reply: the
//! request's, whose module is claimed on a port with a user list as the owner's bridge
//! does; the reply's, read as an importer reads the owner's answer to its connection.
//! Whatever the bytes, each is read as a value and refused by name if it makes no sense.

#![no_main]

use imrs_ipc::IpcError;
use imrs_ipc::fuzzing::{connection_answer, request_module};
use imrs_ports::{AnyUser, Name, Port, PortSpec, usage};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|header: &[u8]| {
    let port: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "OWNER").user_list(["ROBOT_1"]));
    if let Some(Some(module)) = request_module(header) {
        assert!(module.len() <= 64);
        match port.claim(&module) {
            Ok(_) => assert_eq!(module, "ROBOT_1"),
            Err(refused) => {
                assert!(refused.to_string().contains("DOUBLE"), "{refused}");
                if !["DOUBLE", "OWNER", "ROBOT_1"].contains(&module.as_str()) {
                    assert_eq!(Name::known(&module), None, "{module:?} was kept");
                }
            }
        }
    }
    let double = Name::from("DOUBLE");
    if let Some(Err(error)) = connection_answer(header, &double, "ROBOT_1") {
        let text = error.to_string();
        assert!(text.contains("DOUBLE"), "{text}");
        assert!(!matches!(error, IpcError::NoOwner { .. }));
    }
});
