//! A payload a peer host wrote — a request, a reply, a broadcast, a connection's answer —
//! decoded as the ports decode it. Whatever the bytes, decoding returns (no panic, no
//! allocation past `MAX_MESSAGE`), and what decodes encodes to a canonical form that decodes
//! to itself.

#![no_main]

use std::fmt::Debug;

use imrs_zenoh::fuzzing::{connection_answer, decode, encode};
use imrs_zenoh::{MAX_MESSAGE, Message};
use libfuzzer_sys::fuzz_target;
use serde::{Deserialize, Serialize};

/// A message of the shapes a cell declares: names, lists, options, enums, arrays, floats.
#[derive(Debug, Serialize, Deserialize)]
struct Pallet {
    line: String,
    joints: Vec<f64>,
    cards: Vec<Card>,
    seq: Option<u64>,
    slot: [u8; 3],
    ok: bool,
}

#[derive(Debug, Serialize, Deserialize)]
enum Card {
    Empty,
    Chip { slot: u8, serial: u32 },
    Scrapped(String, i64),
}

fn canonical<T: Message + Debug>(payload: &[u8]) {
    let Ok(message) = decode::<T>(payload) else {
        return;
    };
    let encoded = encode(&message).expect("a decoded message encodes");
    let again: T = decode(&encoded).expect("an encoded message decodes");
    assert_eq!(
        encode(&again).expect("a decoded message encodes"),
        encoded,
        "{message:?} changed on a round trip"
    );
}

fuzz_target!(|payload: &[u8]| {
    canonical::<u64>(payload);
    canonical::<String>(payload);
    canonical::<Vec<String>>(payload);
    canonical::<(String, u64)>(payload);
    canonical::<Pallet>(payload);
    if let Ok((owner, timeout, wait)) = connection_answer(payload) {
        assert!(owner.len() as u64 <= MAX_MESSAGE);
        if let Some(timeout) = timeout {
            assert!(wait > timeout, "a request waits past its TIMEOUT");
        }
    }
});
