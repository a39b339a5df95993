//! The chip cell recorded and drawn, as `--record` and `--timeline` make them: the MCAP
//! file read back with the mcap crate's own reader, the same seed recorded twice, and the
//! note-6 deadlock of the Appendix's scheme on the timeline.

use std::collections::BTreeMap;
use std::time::Duration;

use cell_example::{CellConfig, FeederPolicy, TimelineConfig, run};
use imrs_core::EventKind;
use imrs_testkit::temp_path;
use serde_json::Value;

fn recorded(name: &str, feeder: FeederPolicy) -> (cell_example::RunRecord, Vec<u8>) {
    let path = temp_path("imrs-chip", name);
    let config = CellConfig {
        hours: 0.05,
        seed: 1985,
        feeder,
        record: Some(path.clone()),
        ..CellConfig::default()
    };
    let record = run(&config).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    (record, bytes)
}

#[test]
fn a_recorded_run_holds_every_event_on_channels_with_schemas_and_an_index() {
    let (record, bytes) = recorded("counts.mcap", FeederPolicy::Appendix);
    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("a summary section");
    assert!(!summary.chunk_indexes.is_empty(), "an index of the chunks");
    assert!(
        summary
            .channels
            .values()
            .all(|channel| channel.schema.is_some())
    );
    let mut on: BTreeMap<String, usize> = BTreeMap::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        *on.entry(message.unwrap().channel.topic.clone())
            .or_default() += 1;
    }
    // A short run keeps every event: the counts are the logs'.
    assert!(record.cell_events.len() < CellConfig::default().kept_events);
    let cell: usize = on
        .iter()
        .filter(|(topic, _)| topic.starts_with("/ports/") || topic.starts_with("/modules/"))
        .map(|(_, n)| n)
        .sum();
    assert_eq!(cell, record.cell_events.len());
    assert_eq!(on["/sim/events"], record.sim_events.len());
    for topic in [
        "/ports/SHARE_FEEDER",
        "/ports/LET_1_GO",
        "/modules/CHIP_IT",
        "/modules/GATE2",
        "/log",
        "/tf",
        "/scene/cell",
        "/scene/parts",
    ] {
        assert!(on.contains_key(topic), "{topic} in {:?}", on.keys());
    }
    // The ports show their values: the pallets that reach the chip station, GATE's replies.
    let values: Vec<Value> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|message| message.unwrap())
        .filter(|message| message.channel.topic == "/ports/READY_TO_CHIP")
        .map(|message| serde_json::from_slice(&message.data).unwrap())
        .collect();
    assert!(
        values.iter().any(|json| json["op"] == "receive"
            && json["message"]
                .as_str()
                .is_some_and(|m| m.starts_with("PalletId("))),
        "{values:?}"
    );
    // Through the bounded buffer too: the cycle times LOAD_IT and CHIP_IT report to GATE.
    let reported = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|message| message.unwrap())
        .filter(|message| message.channel.topic == "/ports/FREQUENCY")
        .map(|message| serde_json::from_slice::<Value>(&message.data).unwrap())
        .any(|json| {
            json["op"] == "send"
                && json["message"]
                    .as_str()
                    .is_some_and(|m| m.starts_with("(0, ") || m.starts_with("(1, "))
        });
    assert!(reported, "FREQUENCY shows the cycle times sent on it");
    let summed = {
        let path = temp_path("imrs-chip", "summed.mcap");
        std::fs::write(&path, &bytes).unwrap();
        let summary = imrs_record::read_summary(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        summary
    };
    assert_eq!(summed.messages, on.values().sum::<usize>() as u64);
    assert_eq!(summed.span.unwrap().1, Duration::from_secs(180));
}

#[test]
fn the_same_seed_records_the_same_messages_in_the_same_order_at_the_same_times() {
    let messages = |bytes: &[u8]| -> Vec<(String, u64, Vec<u8>)> {
        mcap::MessageStream::new(bytes)
            .unwrap()
            .map(|message| {
                let message = message.unwrap();
                (
                    message.channel.topic.clone(),
                    message.log_time,
                    message.data.to_vec(),
                )
            })
            .collect()
    };
    let (_, first) = recorded("first.mcap", FeederPolicy::Arbiter);
    let (_, second) = recorded("second.mcap", FeederPolicy::Arbiter);
    let (first, second) = (messages(&first), messages(&second));
    assert!(first.len() > 1000, "{}", first.len());
    assert!(first == second, "the recordings differ");
}

#[test]
fn recording_changes_nothing_the_cell_does() {
    let plain = run(&CellConfig {
        hours: 0.05,
        feeder: FeederPolicy::Appendix,
        ..CellConfig::default()
    })
    .unwrap();
    let (recorded, _) = recorded("same.mcap", FeederPolicy::Appendix);
    // The chip cell observes its primitives whether it records or not (its report counts
    // the time lost to deadlocks from the waits): the recording is a pure onlooker.
    assert!(plain.cell_events == recorded.cell_events);
    let shown = plain.cell_events.iter().any(|event| {
        matches!(&event.kind, EventKind::Received { observed: Some(observed), .. }
            if observed.message.as_deref().is_some_and(|m| m.starts_with("PalletId(")))
    });
    assert!(shown, "the chip cell's ports show their values");
    assert_eq!(plain.sim_events, recorded.sim_events);
}

#[test]
fn the_timeline_of_the_appendix_scheme_shows_its_deadlock() {
    let path = temp_path("imrs-chip", "appendix.svg");
    let config = CellConfig {
        hours: 0.05,
        feeder: FeederPolicy::Appendix,
        timeline: Some(TimelineConfig {
            path: path.clone(),
            from: Duration::ZERO,
            span: Duration::from_secs(120),
        }),
        ..CellConfig::default()
    };
    run(&config).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    for label in [
        "CHIP_IT",
        "CHIP_IT2",
        "GATE",
        "zone: chip-robot-A",
        "deadlock CHIP_IT",
    ] {
        assert!(svg.contains(label), "{label} in the timeline");
    }
    assert!(svg.matches("<rect").count() > 100);
}

#[test]
fn a_recording_that_cannot_be_written_is_refused_by_name() {
    let config = CellConfig {
        hours: 0.01,
        record: Some("/nonexistent-directory/cell.mcap".into()),
        ..CellConfig::default()
    };
    let refused = run(&config).unwrap_err().to_string();
    assert!(
        refused.starts_with("/nonexistent-directory/cell.mcap: cannot be written"),
        "{refused}"
    );
}

#[test]
fn the_timeline_keeps_only_its_window_however_long_the_run() {
    let draw = |hours: f64| {
        let path = temp_path("imrs-chip", &format!("window-{hours}.svg"));
        let config = CellConfig {
            hours,
            feeder: FeederPolicy::Appendix,
            timeline: Some(TimelineConfig {
                path: path.clone(),
                from: Duration::from_secs(20),
                span: Duration::from_secs(60),
            }),
            ..CellConfig::default()
        };
        run(&config).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        svg
    };
    // Four times the run, the same picture: nothing after the window was kept.
    let (short, long) = (draw(0.05), draw(0.2));
    assert!(short.contains("deadlock CHIP_IT"));
    assert!(short == long, "the longer run drew something else");
}
