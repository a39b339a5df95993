//! Reading a recording back: a whole one is summed up; a truncated one, random bytes, an
//! empty file or a missing one give a clear error naming the file, never a panic.

mod common;

use common::run;
use imrs_record::{RecordError, Recorder, read_summary};
use imrs_testkit::temp_path;

fn recorded() -> Vec<u8> {
    let path = temp_path("imrs-record", "whole.mcap");
    let recorder = Recorder::create(&path).unwrap();
    run(Some(&recorder), None);
    recorder.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    bytes
}

fn summary_of(name: &str, bytes: &[u8]) -> Result<imrs_record::RecordingSummary, RecordError> {
    let path = temp_path("imrs-record", name);
    std::fs::write(&path, bytes).unwrap();
    let read = read_summary(&path);
    std::fs::remove_file(&path).unwrap();
    read
}

#[test]
fn a_whole_recording_is_summed_up() {
    let summary = summary_of("summed.mcap", &recorded()).unwrap();
    assert!(summary.indexed);
    assert!(summary.chunks >= 1);
    let topics: Vec<&str> = summary.channels.iter().map(|c| c.topic.as_str()).collect();
    for topic in [
        "/log",
        "/modules/CHIP_IT",
        "/ports/SHARE_FEEDER",
        "/scene/cell",
        "/tf",
    ] {
        assert!(topics.contains(&topic), "{topic} in {topics:?}");
    }
    let (first, last) = summary.span.unwrap();
    assert_eq!(first.as_secs(), 0);
    assert!(last.as_secs() >= 10, "{last:?}");
    let text = summary.to_string();
    assert!(text.contains("summary and index present"), "{text}");
    assert!(text.contains("foxglove.SceneUpdate"), "{text}");
}

#[test]
fn a_truncated_recording_is_refused_with_a_clear_error() {
    let bytes = recorded();
    for cut in [8, bytes.len() / 3, bytes.len() / 2, bytes.len() - 1] {
        let error = summary_of("truncated.mcap", &bytes[..cut])
            .unwrap_err()
            .to_string();
        assert!(error.contains("truncated.mcap"), "{error}");
        assert!(error.contains("truncated after"), "cut at {cut}: {error}");
    }
}

#[test]
fn random_bytes_an_empty_file_and_a_damaged_middle_are_refused_not_panicked_on() {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut random = vec![0; 4096];
    for byte in &mut random {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        *byte = seed as u8;
    }
    let error = summary_of("random.mcap", &random).unwrap_err().to_string();
    assert!(
        error.contains("does not start as an MCAP file does"),
        "{error}"
    );
    let error = summary_of("empty.mcap", &[]).unwrap_err().to_string();
    assert!(error.contains("empty.mcap"), "{error}");
    // Keep the start and the end, spoil the middle: the chunks' checks catch it.
    let mut damaged = recorded();
    let middle = damaged.len() / 2;
    for byte in &mut damaged[middle - 64..middle + 64] {
        *byte ^= 0x5a;
    }
    let error = summary_of("damaged.mcap", &damaged)
        .unwrap_err()
        .to_string();
    assert!(error.contains("not a readable MCAP recording"), "{error}");
    let missing = read_summary(temp_path("imrs-record", "missing.mcap"))
        .unwrap_err()
        .to_string();
    assert!(missing.contains("missing.mcap"), "{missing}");
}
