//! What crosses hosts: messages in CDR, the encoding ROS 2 uses.
//!
//! A payload is the message in little-endian CDR after its four-byte encapsulation header
//! (`00 01 00 00`), as `serde` lays it out: a `u64` is `00 01 00 00` then its eight bytes,
//! a struct its fields in order, a `String` a `u32` length (counting a closing zero) then
//! its bytes and the zero. An outside client that speaks CDR reads and writes it.

use byteorder::{BigEndian, LittleEndian};
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::ZenohError;

/// The most bytes of a peer's message that are read when it is decoded. What it decodes
/// into may take more (a list of short strings takes a few times its encoding).
pub const MAX_MESSAGE: u64 = 1 << 20;

/// A message that can cross hosts: any `serde` type, encoded in CDR.
pub trait Message: Serialize + DeserializeOwned + Send + 'static {}

impl<T: Serialize + DeserializeOwned + Send + 'static> Message for T {}

/// The encapsulation header of plain CDR, little-endian and big-endian.
const CDR_LE: [u8; 4] = [0, 1, 0, 0];
const CDR_BE: [u8; 4] = [0, 0, 0, 0];

/// `message` in CDR, as a port writes it; `port` (what it is a message of) is named in an
/// error. Encodings built on this transport use it too (ROS 2's, in `imrs-ros2`).
pub fn encode<T: Serialize>(port: &str, message: &T) -> Result<Vec<u8>, ZenohError> {
    let body =
        cdr_encoding::to_vec::<_, LittleEndian>(message).map_err(|error| ZenohError::Encoding {
            port: port.to_owned(),
            reason: format!("cannot encode a message: {error}"),
        })?;
    let mut bytes = Vec::with_capacity(CDR_LE.len() + body.len());
    bytes.extend_from_slice(&CDR_LE);
    bytes.extend_from_slice(&body);
    Ok(bytes)
}

/// The message `bytes` hold, for `port`; refused if they are not one, or are longer than
/// [`MAX_MESSAGE`]. A message in big-endian CDR is read too.
///
/// Read in place: a length a peer wrote is checked against the bytes that are there before
/// anything is made of it, so a message claiming more than it carries allocates nothing.
pub fn decode<T: DeserializeOwned>(port: &str, bytes: &[u8]) -> Result<T, ZenohError> {
    let refused = |reason: String| ZenohError::Encoding {
        port: port.to_owned(),
        reason,
    };
    if bytes.len() as u64 > MAX_MESSAGE + CDR_LE.len() as u64 {
        return Err(refused(format!(
            "a message of {} bytes, past the bound of {MAX_MESSAGE}",
            bytes.len()
        )));
    }
    let (header, body) = bytes
        .split_at_checked(CDR_LE.len())
        .ok_or_else(|| refused("not a message of this port: shorter than CDR's header".into()))?;
    let decoded = match <[u8; 4]>::try_from(header) {
        Ok(CDR_LE) => cdr_encoding::from_bytes::<T, LittleEndian>(body),
        Ok(CDR_BE) => cdr_encoding::from_bytes::<T, BigEndian>(body),
        _ => {
            return Err(refused(format!(
                "not a message of this port: its header {header:02x?} is not plain CDR"
            )));
        }
    };
    let (message, read) =
        decoded.map_err(|error| refused(format!("not a message of this port: {error}")))?;
    // What follows the message may only be the zeros that round it to four bytes.
    let rest = body.get(read..).unwrap_or_default();
    let padding = rest.is_empty()
        || (rest.len() <= 3 && (read + rest.len()) % 4 == 0 && rest.iter().all(|&byte| byte == 0));
    if !padding {
        return Err(refused(format!(
            "not a message of this port: {} bytes follow it",
            rest.len()
        )));
    }
    Ok(message)
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
        // A length that claims more than the message carries allocates nothing: a string
        // of 3 GB in twelve bytes (found by the fuzzer, `fuzz/`).
        for claim in [
            &[0, 1, 0, 0, 255, 255, 255, 255][..],
            &[0, 1, 0, 0, 0x08, 0x00, 0x00, 0xb4, b'A', 0][..],
        ] {
            let error = decode::<Vec<u8>>("DOUBLE", claim).unwrap_err();
            assert!(error.to_string().contains("DOUBLE"), "{error}");
            let error = decode::<String>("DOUBLE", claim).unwrap_err();
            assert!(error.to_string().contains("DOUBLE"), "{error}");
        }
        let error = decode::<u64>("DOUBLE", &[7, 7, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0]).unwrap_err();
        assert!(error.to_string().contains("not plain CDR"), "{error}");
        // Bytes after the message, past its padding, are refused; the padding is not.
        let mut padded = encode("P", &7_u8).unwrap();
        padded.extend([0, 0, 0]);
        assert_eq!(decode::<u8>("P", &padded).unwrap(), 7);
        padded.push(0);
        let error = decode::<u8>("P", &padded).unwrap_err();
        assert!(error.to_string().contains("4 bytes follow it"), "{error}");
        // Zeros that do not round the message to four bytes are no padding.
        let mut short = encode("P", &7_u8).unwrap();
        short.extend([0, 0]);
        assert!(decode::<u8>("P", &short).is_err());
    }

    #[test]
    fn a_message_past_the_bound_is_refused_unread() {
        let mut bytes = encode("P", &vec![0_u8; MAX_MESSAGE as usize]).unwrap();
        assert!(decode::<Vec<u8>>("P", &bytes).is_err());
        bytes.truncate(MAX_MESSAGE as usize);
        let error = decode::<Vec<u8>>("P", &bytes).unwrap_err();
        assert!(error.to_string().contains("not a message"), "{error}");
    }

    #[test]
    fn a_struct_crosses_in_either_byte_order() {
        let message = ("ROBOT_1".to_owned(), 300_u64, vec![1.5_f64, -2.0]);
        let bytes = encode("P", &message).unwrap();
        assert_eq!(
            decode::<(String, u64, Vec<f64>)>("P", &bytes).unwrap(),
            message
        );
        let mut big = CDR_BE.to_vec();
        big.extend(cdr_encoding::to_vec::<_, BigEndian>(&message).unwrap());
        assert_eq!(
            decode::<(String, u64, Vec<f64>)>("P", &big).unwrap(),
            message
        );
    }
}
