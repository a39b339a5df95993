//! The MCAP recording of a run, read back with the mcap crate's own reader: every channel
//! with a schema, counts that match the event logs, a summary and an index, a scene in
//! Foxglove's schemas that decodes and agrees with rapier, and the same bytes of messages
//! for the same run.

mod common;

use std::collections::BTreeMap;

use common::{name, run};
use foxglove::messages::{FrameTransforms, Log, SceneUpdate};
use imrs_core::EventKind;
use imrs_record::{Recorder, read_summary};
use imrs_testkit::temp_path;
use prost::Message as _;
use serde_json::Value;

/// One message as read back: topic, schema name, log time, bytes.
type Read = (String, String, u64, Vec<u8>);

fn record(file: &str) -> (common::Ran, Vec<Read>, std::path::PathBuf) {
    let path = temp_path("imrs-record", file);
    let recorder = Recorder::create(&path).unwrap();
    let ran = run(Some(&recorder), None);
    let recorded = recorder.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let messages: Vec<Read> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|message| {
            let message = message.unwrap();
            let schema = message
                .channel
                .schema
                .as_ref()
                .map_or(String::new(), |s| s.name.clone());
            (
                message.channel.topic.clone(),
                schema,
                message.log_time,
                message.data.to_vec(),
            )
        })
        .collect();
    assert_eq!(recorded.messages, messages.len() as u64);
    (ran, messages, path)
}

#[test]
fn every_event_is_on_its_channel_with_a_schema_and_the_file_has_its_summary_and_index() {
    let (ran, messages, path) = record("counts.mcap");
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("a summary section");
    assert!(!summary.chunk_indexes.is_empty(), "a chunk index");
    let stats = summary.stats.expect("statistics");
    assert_eq!(stats.message_count, messages.len() as u64);
    for channel in summary.channels.values() {
        let schema = channel
            .schema
            .as_ref()
            .unwrap_or_else(|| panic!("{} has a schema", channel.topic));
        assert!(!schema.data.is_empty(), "{}", channel.topic);
    }

    let mut on: BTreeMap<&str, usize> = BTreeMap::new();
    for (topic, ..) in &messages {
        *on.entry(topic.as_str()).or_default() += 1;
    }
    // Every cell event, on its port's channel or its module's.
    let port_or_module = on
        .iter()
        .filter(|(topic, _)| topic.starts_with("/ports/") || topic.starts_with("/modules/"))
        .map(|(_, n)| n)
        .sum::<usize>();
    assert_eq!(port_or_module, ran.events.len());
    let queries = ran
        .events
        .iter()
        .filter(|event| {
            matches!(&event.kind, EventKind::Queried { port, .. } if *port == name("SHARE_FEEDER1"))
        })
        .count();
    let on_port = messages
        .iter()
        .filter(|(topic, _, _, data)| {
            topic == "/ports/SHARE_FEEDER1"
                && serde_json::from_slice::<Value>(data).unwrap()["op"] == "query"
        })
        .count();
    assert_eq!((on_port, queries), (1, 1));
    // The port shows its values: the query and the answer CRIT_SECTION gave.
    let query = messages
        .iter()
        .filter(|(topic, ..)| topic == "/ports/SHARE_FEEDER1")
        .map(|(.., data)| serde_json::from_slice::<Value>(data).unwrap())
        .find(|json| json["op"] == "query")
        .unwrap();
    assert_eq!(
        (&query["message"], &query["reply"]),
        (&Value::from("()"), &Value::from("1"))
    );
    // Every measured fact.
    assert_eq!(on["/sim/events"], ran.sim_events.len());
    // The deadlock, the timeout and the port failure reach the log panel.
    let logged: Vec<String> = messages
        .iter()
        .filter(|(topic, ..)| topic == "/log")
        .map(|(.., data)| Log::decode(data.as_slice()).unwrap().message)
        .collect();
    for expected in [
        "deadlock: ",
        "raised SHARE_FEEDER.TIMEOUT",
        "SHARE_FEEDER: ",
    ] {
        assert!(
            logged.iter().any(|line| line.contains(expected)),
            "{expected} in {logged:?}"
        );
    }
    // The summary the reader prints agrees.
    let read = read_summary_of(&bytes);
    assert_eq!(read.messages, messages.len() as u64);
    assert!(read.indexed);
}

fn read_summary_of(bytes: &[u8]) -> imrs_record::RecordingSummary {
    let path = temp_path("imrs-record", "again.mcap");
    std::fs::write(&path, bytes).unwrap();
    let summary = read_summary(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    summary
}

#[test]
fn the_scene_decodes_in_foxglove_schemas_and_agrees_with_rapier() {
    let (ran, messages, path) = record("scene.mcap");
    std::fs::remove_file(&path).unwrap();
    let mut schemas = BTreeMap::new();
    for (topic, schema, ..) in &messages {
        schemas.insert(topic.as_str(), schema.as_str());
    }
    assert_eq!(schemas["/tf"], "foxglove.FrameTransforms");
    assert_eq!(schemas["/scene/cell"], "foxglove.SceneUpdate");
    assert_eq!(schemas["/scene/parts"], "foxglove.SceneUpdate");
    assert_eq!(schemas["/log"], "foxglove.Log");

    // The fixed scene: a shape for each of the twelve arm links, locked to its frame.
    let fixed: Vec<SceneUpdate> = messages
        .iter()
        .filter(|(topic, ..)| topic == "/scene/cell")
        .map(|(.., data)| SceneUpdate::decode(data.as_slice()).unwrap())
        .collect();
    assert_eq!(fixed.len(), 1);
    let links: Vec<_> = fixed[0]
        .entities
        .iter()
        .filter(|entity| entity.id.contains("/link"))
        .collect();
    assert_eq!(links.len(), 12);
    assert!(
        links
            .iter()
            .all(|link| link.frame_locked && link.id == link.frame_id)
    );

    // Replaying every transform gives where rapier has the links at the end.
    let mut frames = BTreeMap::new();
    for (topic, _, at, data) in &messages {
        if topic == "/tf" {
            for transform in FrameTransforms::decode(data.as_slice()).unwrap().transforms {
                assert_eq!(transform.parent_frame_id, "world");
                let stamp = transform.timestamp.unwrap();
                assert_eq!(
                    u64::from(stamp.sec()) * 1_000_000_000 + u64::from(stamp.nsec()),
                    *at
                );
                frames.insert(transform.child_frame_id, transform.translation.unwrap());
            }
        }
    }
    for arm in &ran.scene.arms {
        for (index, link) in arm.links.iter().enumerate() {
            let frame = imrs_record::scene::link_frame(arm.robot, index);
            let at = &frames[&frame];
            let recorded = [at.x, at.y, at.z];
            for (axis, value) in recorded.iter().enumerate() {
                assert!(
                    (value - f64::from(link.centre[axis])).abs() < 1e-6,
                    "{frame}: {recorded:?} against {:?}",
                    link.centre
                );
            }
        }
    }
    // The zone was shown occupied while a robot reached into it, and clear at the end.
    let zone_states: Vec<String> = messages
        .iter()
        .filter(|(topic, ..)| topic == "/scene/parts")
        .flat_map(|(.., data)| SceneUpdate::decode(data.as_slice()).unwrap().entities)
        .filter(|entity| entity.id == "feeder-zone")
        .map(|entity| entity.metadata[0].value.clone())
        .collect();
    assert!(zone_states.contains(&"1".to_string()), "{zone_states:?}");
    assert_eq!(zone_states.last().map(String::as_str), Some("0"));
}

/// The JSON messages against the JSON schema their channel names: every required field
/// present, every field of the type the schema gives it.
#[test]
fn the_json_messages_match_their_json_schemas() {
    let path = temp_path("imrs-record", "json.mcap");
    let recorder = Recorder::create(&path).unwrap();
    run(Some(&recorder), None);
    recorder.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let mut titles = std::collections::BTreeSet::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        if message.channel.message_encoding != "json" {
            continue;
        }
        let schema = message.channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "jsonschema");
        let schema: Value = serde_json::from_slice(&schema.data).unwrap();
        let value: Value = serde_json::from_slice(&message.data).unwrap();
        for required in schema["required"].as_array().unwrap() {
            assert!(
                value.get(required.as_str().unwrap()).is_some(),
                "{required} in {value}"
            );
        }
        for (field, content) in value.as_object().unwrap() {
            let kind = schema["properties"][field]["type"]
                .as_str()
                .unwrap_or_else(|| panic!("{field} of {value} is in {}", schema["title"]));
            let fits = match kind {
                "string" => content.is_string(),
                "number" => content.is_number(),
                "integer" => content.is_u64() || content.is_i64(),
                "array" => content.is_array(),
                other => panic!("a type the schemas do not use: {other}"),
            };
            assert!(fits, "{field} of {value} is a {kind}");
            if let Some(allowed) = schema["properties"][field]["enum"].as_array() {
                assert!(allowed.contains(content), "{field} of {value}");
            }
        }
        titles.insert(schema["title"].as_str().unwrap().to_string());
    }
    assert_eq!(
        titles,
        ["imrs.ModuleEvent", "imrs.PortEvent", "imrs.SimEvent"]
            .map(String::from)
            .into()
    );
}

#[test]
fn the_same_run_records_the_same_messages_in_the_same_order_at_the_same_times() {
    let (_, first, path) = record("first.mcap");
    std::fs::remove_file(&path).unwrap();
    let (_, second, path) = record("second.mcap");
    std::fs::remove_file(&path).unwrap();
    assert_eq!(first.len(), second.len());
    assert!(first == second, "the two recordings differ");
}

#[test]
fn a_recording_is_finished_once_and_a_file_that_cannot_be_made_is_named() {
    let path = temp_path("imrs-record", "twice.mcap");
    let recorder = Recorder::create(&path).unwrap();
    recorder.finish().unwrap();
    let again = recorder.finish().unwrap_err().to_string();
    assert!(again.contains("already finished"), "{again}");
    assert!(again.starts_with(&path.display().to_string()), "{again}");
    std::fs::remove_file(&path).unwrap();
    let nowhere = Recorder::create("/nonexistent-directory/cell.mcap").unwrap_err();
    assert!(
        nowhere
            .to_string()
            .starts_with("/nonexistent-directory/cell.mcap: "),
        "{nowhere}"
    );
}

#[test]
fn two_recordings_made_at_once_on_two_threads_never_mix() {
    let (_, alone, path) = record("alone.mcap");
    std::fs::remove_file(&path).unwrap();
    let together: Vec<Vec<Read>> = std::thread::scope(|scope| {
        let makers: Vec<_> = ["first-of-two.mcap", "second-of-two.mcap"]
            .map(|file| {
                scope.spawn(move || {
                    let (_, messages, path) = record(file);
                    std::fs::remove_file(&path).unwrap();
                    messages
                })
            })
            .into_iter()
            .collect();
        makers
            .into_iter()
            .map(|maker| maker.join().unwrap())
            .collect()
    });
    for messages in together {
        assert_eq!(messages.len(), alone.len());
        assert!(messages == alone, "a recording made beside another differs");
    }
}

#[test]
fn messages_that_come_after_finish_are_dropped_and_the_file_stays_whole() {
    let path = temp_path("imrs-record", "finished-early.mcap");
    let recorder = Recorder::create(&path).unwrap();
    let finished = recorder.finish().unwrap();
    let before = std::fs::read(&path).unwrap();
    // The whole cell runs with the finished recorder subscribed.
    run(Some(&recorder), None);
    assert_eq!(std::fs::read(&path).unwrap(), before);
    let summary = read_summary(&path).unwrap();
    assert!(summary.indexed);
    assert_eq!(summary.messages, finished.messages);
    std::fs::remove_file(&path).unwrap();
}
