//! What `rmw_zenoh` attaches to every publication, query and reply (`attachment_helpers`,
//! ROS 2 Jazzy from 0.2.4, Kilted, Rolling): the sequence number, the source's timestamp
//! and the source's GID, as zenoh-ext serializes them: 33 bytes.

use std::time::{SystemTime, UNIX_EPOCH};

/// An attachment: which message of which endpoint, sent when.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Attachment {
    /// The message's number at its source, from 1. A reply carries its request's.
    pub sequence_number: i64,
    /// When it was sent, in nanoseconds since the Unix epoch.
    pub source_timestamp: i64,
    /// The source endpoint's GID. A reply carries its client's.
    pub source_gid: [u8; 16],
}

/// Its length: two `i64`s, the GID's length (zenoh-ext writes an array as a sequence, its
/// length first, as a LEB128 varint: one byte), the GID.
const LENGTH: usize = 8 + 8 + 1 + 16;

impl Attachment {
    /// Message `sequence_number` of the endpoint `source_gid`, sent now.
    pub fn now(sequence_number: i64, source_gid: [u8; 16]) -> Self {
        let source_timestamp = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |since| {
                i64::try_from(since.as_nanos()).unwrap_or(i64::MAX)
            });
        Self {
            sequence_number,
            source_timestamp,
            source_gid,
        }
    }

    /// As zenoh carries it.
    pub fn to_bytes(&self) -> [u8; LENGTH] {
        let mut bytes = [0; LENGTH];
        bytes[..8].copy_from_slice(&self.sequence_number.to_le_bytes());
        bytes[8..16].copy_from_slice(&self.source_timestamp.to_le_bytes());
        bytes[16] = 16;
        bytes[17..].copy_from_slice(&self.source_gid);
        bytes
    }

    /// Read from what a peer attached; `None` unless it is one.
    pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let bytes: &[u8; LENGTH] = bytes.try_into().ok()?;
        if bytes[16] != 16 {
            return None;
        }
        let word = |at: usize| {
            let mut word = [0; 8];
            word.copy_from_slice(&bytes[at..at + 8]);
            i64::from_le_bytes(word)
        };
        let mut source_gid = [0; 16];
        source_gid.copy_from_slice(&bytes[17..]);
        Some(Self {
            sequence_number: word(0),
            source_timestamp: word(8),
            source_gid,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_attachment_is_33_bytes_and_reads_back() {
        let attachment = Attachment {
            sequence_number: 1,
            source_timestamp: 0x0102_0304_0506_0708,
            source_gid: [7; 16],
        };
        let bytes = attachment.to_bytes();
        assert_eq!(&bytes[..8], &[1, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(&bytes[8..16], &[8, 7, 6, 5, 4, 3, 2, 1]);
        assert_eq!(bytes[16], 16);
        assert_eq!(Attachment::from_bytes(&bytes), Some(attachment));
        assert_eq!(Attachment::from_bytes(&bytes[..32]), None);
        let mut wrong_length = bytes;
        wrong_length[16] = 15;
        assert_eq!(Attachment::from_bytes(&wrong_length), None);
    }
}
