//! The code that reads what a peer host wrote — payloads and attachments — reached from
//! outside for the fuzz targets in `fuzz/`. Built only under `cfg(fuzzing)`, which
//! `cargo fuzz` sets: not part of the API.

use std::borrow::Cow;
use std::time::Duration;

use crate::ZenohError;
use crate::message::Message;

/// The message a payload holds, decoded as every request, reply and broadcast is.
pub fn decode<T: Message>(payload: &[u8]) -> Result<T, ZenohError> {
    crate::message::decode("FUZZ", payload)
}

/// `message` encoded as it crosses.
pub fn encode<T: Message>(message: &T) -> Result<Vec<u8>, ZenohError> {
    crate::message::encode("FUZZ", message)
}

/// The module a delivery's attachment names, as a user's host reads it.
pub fn sender(attachment: &[u8]) -> Result<Cow<'_, str>, String> {
    crate::export::module_from(Cow::Borrowed(attachment))
}

/// The module a request's or a connection's key names, as the owner's host reads it.
pub fn module_in(key: &str) -> Result<&str, String> {
    crate::export::module_in(key)
}

/// The owner's answer to a connection, as the importer reads it: the owner's name, the
/// port's TIMEOUT, and how long each request then waits for its reply.
pub fn connection_answer(
    payload: &[u8],
) -> Result<(String, Option<Duration>, Duration), ZenohError> {
    let connected: crate::connected::Connected = crate::message::decode("FUZZ", payload)?;
    let (timeout, wait) = crate::import::waits(&connected);
    Ok((connected.owner, timeout, wait))
}
