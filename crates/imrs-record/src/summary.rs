//! Reading a recording back: its channels, how many messages each holds, and the time it
//! spans, with a clear error for a file that is truncated or not an MCAP recording at all.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;
use std::time::Duration;

use crate::error::RecordError;

/// One channel of a recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelSummary {
    /// Its topic.
    pub topic: String,
    /// Its schema's name, if it has one.
    pub schema: Option<String>,
    /// How its messages are encoded.
    pub encoding: String,
    /// Messages on it.
    pub messages: u64,
}

/// What a recording holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordingSummary {
    /// Its channels, by topic.
    pub channels: Vec<ChannelSummary>,
    /// Messages in all.
    pub messages: u64,
    /// The first and the last message's time, from the clock's start.
    pub span: Option<(Duration, Duration)>,
    /// Compressed chunks the messages are in.
    pub chunks: usize,
    /// Whether the file ends with a summary section and a chunk index (a finished recording).
    pub indexed: bool,
}

/// Reads the recording at `path`, checking every message, and sums it up. A truncated file,
/// or one that is not MCAP, is an error naming the file and what is wrong, never a panic.
pub fn read_summary(path: impl AsRef<Path>) -> Result<RecordingSummary, RecordError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|error| RecordError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let corrupt = |error: String| RecordError::Corrupt {
        path: path.to_path_buf(),
        error,
    };
    if !bytes.starts_with(MAGIC) {
        return Err(corrupt("it does not start as an MCAP file does".into()));
    }
    if !bytes.ends_with(MAGIC) || bytes.len() < 2 * MAGIC.len() {
        return Err(corrupt(format!(
            "it starts as MCAP but does not end as one: truncated after {} bytes, or never \
             finished",
            bytes.len()
        )));
    }
    // The mcap reader parses untrusted bytes; should it ever panic on them, that is a
    // corrupt file to the caller too, not a crash.
    let read = std::panic::catch_unwind(|| summarise(&bytes));
    read.map_err(|_| corrupt("the reader could not parse it".into()))?
        .map_err(|error| corrupt(error.to_string()))
}

/// The bytes an MCAP file starts and ends with.
const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Reads every record once with every check the format offers: the chunks', the data
/// section's and the summary section's CRCs, and nothing after the end.
fn validate(bytes: &[u8]) -> Result<(), mcap::McapError> {
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let options = LinearReaderOptions::default()
        .with_validate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true)
        .with_check_finishes_after_end_magic(true);
    let mut reader = LinearReader::new_with_options(options);
    let mut at = 0;
    while let Some(event) = reader.next_event() {
        if let LinearReadEvent::ReadRequest(wanted) = event? {
            let take = wanted.min(bytes.len() - at);
            reader.insert(take).copy_from_slice(&bytes[at..at + take]);
            reader.notify_read(take);
            at += take;
        }
    }
    Ok(())
}

fn summarise(bytes: &[u8]) -> Result<RecordingSummary, mcap::McapError> {
    validate(bytes)?;
    let index = mcap::Summary::read(bytes)?;
    let mut channels: BTreeMap<String, ChannelSummary> = BTreeMap::new();
    let (mut messages, mut span) = (0, None::<(u64, u64)>);
    for message in mcap::MessageStream::new(bytes)? {
        let message = message?;
        let channel = &message.channel;
        channels
            .entry(channel.topic.clone())
            .or_insert_with(|| ChannelSummary {
                topic: channel.topic.clone(),
                schema: channel.schema.as_ref().map(|schema| schema.name.clone()),
                encoding: channel.message_encoding.clone(),
                messages: 0,
            })
            .messages += 1;
        messages += 1;
        let at = message.log_time;
        span = Some(span.map_or((at, at), |(first, last)| (first.min(at), last.max(at))));
    }
    // A finished recording has a summary with its statistics, and an index entry for each
    // chunk; one that holds no message has no chunk to index.
    let (chunks, indexed) = index.as_ref().map_or((0, false), |index| {
        let chunks = index.chunk_indexes.len();
        (
            chunks,
            index.stats.is_some() && (chunks > 0 || messages == 0),
        )
    });
    Ok(RecordingSummary {
        channels: channels.into_values().collect(),
        messages,
        span: span.map(|(first, last)| (Duration::from_nanos(first), Duration::from_nanos(last))),
        chunks,
        indexed,
    })
}

impl fmt::Display for RecordingSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.span {
            Some((first, last)) => writeln!(
                f,
                "{} messages on {} channels, from {:.3} s to {:.3} s of the cell's clock",
                self.messages,
                self.channels.len(),
                first.as_secs_f64(),
                last.as_secs_f64()
            )?,
            None => writeln!(f, "no messages, {} channels", self.channels.len())?,
        }
        writeln!(
            f,
            "{} chunks, {}",
            self.chunks,
            if self.indexed {
                "summary and index present"
            } else {
                "NO summary or index (the recording was not finished)"
            }
        )?;
        writeln!(f)?;
        writeln!(f, "  {:<36}{:<22}{:>10}", "channel", "schema", "messages")?;
        for channel in &self.channels {
            writeln!(
                f,
                "  {:<36}{:<22}{:>10}",
                channel.topic,
                channel.schema.as_deref().unwrap_or("-"),
                channel.messages
            )?;
        }
        Ok(())
    }
}
