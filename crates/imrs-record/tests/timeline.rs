//! The timeline of a window of a run: sections, waits on peers, zone occupancy measured by
//! rapier, and the deadlock of Shin 1985's note 6 where a reader sees it at a glance.

mod common;

use common::{run, secs};
use imrs_record::Timeline;
use imrs_record::timeline::{MarkKind, SpanKind};
use imrs_sim::SimEventKind;
use imrs_testkit::temp_path;

#[test]
fn the_deadlock_shows_as_both_robots_waiting_on_each_other_and_a_mark() {
    let timeline = Timeline::new(secs(0), secs(40));
    let ran = run(None, Some(&timeline));
    let marks = timeline.marks();
    let deadlock = marks
        .iter()
        .find(|mark| mark.kind == MarkKind::Deadlock)
        .expect("the deadlock is marked");
    assert_eq!(deadlock.at, 0.0);
    assert!(deadlock.label.contains("CHIP_IT"), "{deadlock:?}");
    // CHIP_IT's query times out at 3 s (its TIMEOUT): marked on its row.
    assert!(
        marks.iter().any(|mark| mark.kind == MarkKind::Timeout
            && mark.label == "SHARE_FEEDER.TIMEOUT"
            && (mark.at - 3.0).abs() < 1e-9),
        "{marks:?}"
    );
    let rows = timeline.rows();
    let row = |name: &str| rows.iter().find(|row| row.name == name).expect(name);
    // Both wait on each other from 0 s: CHIP_IT until its timeout at 3 s, CHIP_IT2 until
    // its query is answered once CHIP_IT backs off.
    for (robot, port) in [("CHIP_IT", "SHARE_FEEDER"), ("CHIP_IT2", "SHARE_FEEDER1")] {
        let waits: Vec<_> = row(robot)
            .spans
            .iter()
            .filter(|span| span.kind == SpanKind::Blocked(port.into()))
            .collect();
        assert!(
            waits.iter().any(|span| span.from == 0.0 && span.to >= 3.0),
            "{robot}: {waits:?}"
        );
    }
    // Sections: each robot grasped and inserted once; CHIP_IT backed off once.
    for robot in ["CHIP_IT", "CHIP_IT2"] {
        for section in ["GRASP", "INSERT"] {
            let count = row(robot)
                .spans
                .iter()
                .filter(|span| span.kind == SpanKind::Section(section.into()))
                .count();
            assert_eq!(count, 1, "{robot} {section}");
        }
    }
    // The zone rows come from rapier's measurements, span for span.
    let entered = ran
        .sim_events
        .iter()
        .filter(|event| matches!(event.kind, SimEventKind::ZoneEntered { .. }))
        .count();
    let in_zone = rows
        .iter()
        .flat_map(|row| &row.spans)
        .filter(|span| span.kind == SpanKind::InZone)
        .count();
    assert!(entered >= 2, "both robots reached into the zone");
    assert_eq!(in_zone, entered);
}

#[test]
fn only_the_window_is_kept() {
    let timeline = Timeline::new(secs(10), secs(20));
    run(None, Some(&timeline));
    let rows = timeline.rows();
    assert!(rows.iter().all(|row| {
        row.spans
            .iter()
            .all(|span| span.from >= 10.0 && span.to <= 20.0 && span.from < span.to)
    }));
    // The deadlock at 0 s lies outside.
    assert!(timeline.marks().iter().all(|mark| mark.at >= 10.0));
}

#[test]
fn the_picture_is_drawn_with_a_row_per_module_and_robot() {
    let timeline = Timeline::new(secs(0), secs(40));
    run(None, Some(&timeline));
    let path = temp_path("imrs-record", "timeline.svg");
    timeline.render_svg(&path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(80)]);
    for label in [
        "CHIP_IT",
        "CHIP_IT2",
        "zone: chip-robot-A",
        "zone: chip-robot-B",
        "deadlock",
        "GRASP",
        "waiting on a peer",
    ] {
        assert!(svg.contains(label), "{label} in the picture");
    }
    // The bars themselves, by colour: a GRASP and an INSERT for each robot (one more of each
    // in the key), the waits on each other, and each robot's time in the zone.
    let bars = |fill: &str| svg.matches(&format!("fill=\"{fill}\"")).count();
    assert_eq!(bars("#4285F4"), 2 + 1, "GRASP");
    assert_eq!(bars("#34A853"), 2 + 1, "INSERT");
    assert!(bars("#EF6C00") > 2, "waits");
    assert!(bars("#FFC107") > 2, "in the zone");
}

#[test]
fn a_picture_that_cannot_be_written_is_an_error_naming_the_file() {
    let timeline = Timeline::new(secs(0), secs(40));
    run(None, Some(&timeline));
    let error = timeline
        .render_svg("/nonexistent-directory/timeline.svg")
        .unwrap_err();
    assert!(
        error
            .to_string()
            .starts_with("/nonexistent-directory/timeline.svg"),
        "{error}"
    );
}
