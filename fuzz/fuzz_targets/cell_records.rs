//! The chip cell's own records as a peer process or host wrote them: a device call the
//! world reads, the answer a line reads, a chip robot's zone word the arbiter reads and its
//! reservation the coordinator reads. Each is read both ways it crosses — in place from
//! shared memory (iceoryx2) and decoded from a payload (zenoh). Whatever the bytes, reading
//! returns (no panic, no allocation past the fuzzer's limit); what reads as a call or an
//! answer writes back to a record that reads the same; a reservation holds no more poses than
//! a record can, and the coordinator weighs it against another without a panic.

#![no_main]

use cell_example::devices::{DeviceAnswer, DeviceCall};
use cell_example::reservation::{MAX_POSES, Reservation};
use cell_example::zone_asker::ZoneAsker;
use imrs_coord::zones::Reservations;
use imrs_ipc::FromBytes;
use imrs_zenoh::Message;
use imrs_zenoh::fuzzing::{decode, encode};
use libfuzzer_sys::fuzz_target;

/// A call that reads as an op is written back, by `DeviceCall::new`, as a call that reads
/// as the same op (compared by its encoding, so that a NaN point is equal to itself).
fn call(call: &DeviceCall) {
    let Some(op) = call.op() else {
        return;
    };
    let written = DeviceCall::new(op).in_run(call.run());
    let again = written.op().expect("a call DeviceCall::new wrote reads");
    assert_eq!(
        encode(&DeviceCall::new(again).in_run(call.run())).unwrap(),
        encode(&written).unwrap(),
        "{op:?} changed when written back"
    );
}

/// The same for an answer.
fn answer(answer: &DeviceAnswer) {
    let Some(read) = answer.answer() else {
        return;
    };
    let written = DeviceAnswer::new(&read);
    let again = written
        .answer()
        .expect("an answer DeviceAnswer::new wrote reads");
    assert_eq!(
        encode(&DeviceAnswer::new(&again)).unwrap(),
        encode(&written).unwrap(),
        "{read:?} changed when written back"
    );
}

fn zone_asker(asker: &ZoneAsker) {
    let _ = (asker.robot().as_str(), asker.line(), asker.run());
}

/// What the coordinator does with a reservation: its sweep, weighed against one held.
fn reservation(reservation: &Reservation, held: &mut Reservations) {
    let _ = format!("{reservation:?} {}", reservation.robot());
    if let Some(sweep) = reservation.sweep() {
        assert!(sweep.len() <= MAX_POSES);
    }
    // As the coordinator weighs it: only a chip robot's.
    if let (Some(_), Some(sweep)) = (reservation.chip_robot(), reservation.sweep()) {
        let _ = held.request(reservation.robot().as_str(), &sweep.to_vec());
        let _ = held.release(reservation.robot().as_str());
    }
}

/// The record read both ways a peer's record reaches a module: in place from the first bytes
/// of a sample, as iceoryx2 reads it, and decoded from a payload, as zenoh does.
fn read<T: FromBytes + Message>(bytes: &[u8]) -> impl Iterator<Item = T> {
    let in_place = T::read_from_prefix(bytes).ok().map(|(record, _)| record);
    in_place.into_iter().chain(decode(bytes).ok())
}

fuzz_target!(|bytes: &[u8]| {
    let mut held = Reservations::new(0.05, 0.03);
    // One reservation held, far from the cell, for the peer's to be weighed against.
    let _ = held.request("CHIP_IT2", &vec![[[9.0, 9.0], [9.5, 9.0], [10.0, 9.0]]]);
    read::<DeviceCall>(bytes).for_each(|read| call(&read));
    read::<DeviceAnswer>(bytes).for_each(|read| answer(&read));
    read::<ZoneAsker>(bytes).for_each(|read| zone_asker(&read));
    read::<Reservation>(bytes).for_each(|read| reservation(&read, &mut held));
});
