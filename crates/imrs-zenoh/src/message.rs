//! What crosses hosts: messages in CDR, the encoding ROS 2 uses.
//!
//! A payload is the message in little-endian CDR after its four-byte encapsulation header
//! (`00 01 00 00`), as `serde` lays it out: a `u64` is `00 01 00 00` then its eight bytes,
//! a struct its fields in order, a `String` a `u32` length (counting a closing zero) then
//! its bytes and the zero. An outside client that speaks CDR reads and writes it.

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::ZenohError;

/// The most bytes of a peer's message that are read when it is decoded. What it decodes
/// into may take more (a list of short strings takes a few times its encoding).
pub const MAX_MESSAGE: u64 = 1 << 20;

/// A message that can cross hosts: any `serde` type, encoded in CDR.
pub trait Message: Serialize + DeserializeOwned + Send + 'static {}

impl<T: Serialize + DeserializeOwned + Send + 'static> Message for T {}

/// `message` in CDR, for `port`.
pub(crate) fn encode<T: Serialize>(port: &str, message: &T) -> Result<Vec<u8>, ZenohError> {
    cdr::serialize::<_, _, cdr::CdrLe>(message, cdr::Infinite).map_err(|error| {
        ZenohError::Encoding {
            port: port.to_owned(),
            reason: format!("cannot encode a message: {error}"),
        }
    })
}

/// The message `bytes` hold, for `port`; refused if they are not one, or would take more
/// than [`MAX_MESSAGE`] bytes.
pub(crate) fn decode<T: DeserializeOwned>(port: &str, bytes: &[u8]) -> Result<T, ZenohError> {
    cdr::deserialize_from::<_, T, _>(bytes, cdr::Bounded(MAX_MESSAGE)).map_err(|error| {
        ZenohError::Encoding {
            port: port.to_owned(),
            reason: format!("not a message of this port: {error}"),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_u64_is_its_header_then_its_bytes_little_endian() {
        let bytes = encode("P", &0x0102_0304_0506_0708_u64).unwrap();
        assert_eq!(bytes, [0, 1, 0, 0, 8, 7, 6, 5, 4, 3, 2, 1]);
        assert_eq!(decode::<u64>("P", &bytes).unwrap(), 0x0102_0304_0506_0708);
    }

    #[test]
    fn bytes_that_are_no_message_are_refused_naming_the_port() {
        let error = decode::<u64>("DOUBLE", &[0, 1, 0, 0, 1]).unwrap_err();
        assert!(
            error.to_string().starts_with("port DOUBLE: not a message"),
            "{error}"
        );
        // A length that claims more than the bound allocates nothing.
        let error = decode::<Vec<u8>>("DOUBLE", &[0, 1, 0, 0, 255, 255, 255, 255]).unwrap_err();
        assert!(error.to_string().contains("DOUBLE"), "{error}");
    }
}
