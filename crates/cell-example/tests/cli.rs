//! The chip cell's command line, as an operator meets it: bad input is refused with a message
//! that names it, and the example never panics on its arguments or its output.

use std::ffi::OsString;
use std::os::unix::ffi::OsStringExt;
use std::process::{Command, Stdio};

use cell_example::{CellConfig, FeederPolicy, RunError, parse, run};
use imrs_testkit::example_binary;

fn args(list: &[&str]) -> Vec<OsString> {
    list.iter().map(OsString::from).collect()
}

#[test]
fn an_argument_that_is_not_utf8_is_refused_by_name() {
    let bad = OsString::from_vec(vec![b'-', b'-', b'h', 0xff, b'u']);
    let refused = parse([OsString::from("--hours"), bad]).unwrap_err();
    assert_eq!(refused.status, 2);
    assert!(
        refused
            .message
            .starts_with("error: argument \"--h\u{fffd}u\" is not valid UTF-8"),
        "{refused}"
    );
}

#[test]
fn flags_parse_into_a_config() {
    let config = parse(args(&[
        "--hours", "2", "--seed", "7", "--feeder", "appendix",
    ]))
    .unwrap();
    assert_eq!(
        (config.hours, config.seed, config.feeder),
        (2.0, 7, FeederPolicy::Appendix)
    );
    let refused = parse(args(&["--hours"])).unwrap_err();
    assert_eq!(refused.status, 2);
    assert!(
        refused
            .message
            .starts_with("error: a value is required for '--hours <H>'"),
        "{refused}"
    );
}

#[test]
fn a_bad_value_is_refused_naming_its_flag_and_what_was_expected() {
    for (flags, expected) in [
        (
            &["--hours", "-3"][..],
            "invalid value '-3' for '--hours <H>': expected a number of hours above 0",
        ),
        (
            &["--feeder", "monitor"][..],
            "invalid value 'monitor' for '--feeder <FEEDER>'",
        ),
        (
            &["--fault", "robot:C@10"][..],
            "invalid value 'robot:C@10' for '--fault <KIND[:WHICH]@TIME>': the line must be A or B",
        ),
        (
            &["--timeline-span", "soon"][..],
            "invalid value 'soon' for '--timeline-span <SECONDS>'",
        ),
        (&["--speedup", "2"][..], "unexpected argument '--speedup'"),
        // A speed-up only means something across processes.
        (
            &["--speed", "2"][..],
            "the following required arguments were not provided:\n  --processes",
        ),
    ] {
        let refused = parse(args(flags)).unwrap_err();
        assert_eq!(refused.status, 2, "{flags:?}");
        assert!(refused.message.contains(expected), "{flags:?}: {refused}");
    }
}

#[test]
fn help_lists_every_flag_with_its_meaning_and_default() {
    let help = parse(args(&["--help"])).unwrap_err();
    assert_eq!(help.status, 0, "{help}");
    for flag in [
        "--hours <H>",
        "[default: 1]",
        "--seed <S>",
        "[default: 1985]",
        "--feeder <FEEDER>",
        "[default: arbiter]",
        "--realtime",
        "--tree",
        "--fault <KIND[:WHICH]@TIME>",
        "--record <FILE.mcap>",
        "--timeline <FILE.svg>",
        "--timeline-from <SECONDS>",
        "--timeline-span <SECONDS>",
        "--no-progress",
        "--processes",
        "--speed <X>",
        "[default: 60]",
    ] {
        assert!(help.message.contains(flag), "{flag:?} in\n{help}");
    }
    // The flags the world sets on the lines' processes are its business, not the user's.
    for hidden in ["--line-process", "--remote", "--epoch"] {
        assert!(!help.message.contains(hidden), "{hidden:?} in\n{help}");
    }
}

#[test]
fn a_fault_after_the_end_of_the_run_is_refused() {
    let config = CellConfig {
        hours: 0.5,
        ..parse(args(&["--fault", "robot:B@45m"])).unwrap()
    };
    let refused = run(&config).unwrap_err();
    assert!(
        matches!(refused, RunError::FaultAfterEnd { .. }),
        "{refused}"
    );
    assert!(
        refused
            .to_string()
            .starts_with("--fault robot:B@2700s: set for after the run's end (0.5 h)"),
        "{refused}"
    );
}

#[test]
fn a_reader_that_stops_reading_does_not_make_the_example_panic() {
    let mut child = Command::new(example_binary("chip_cell"))
        .args(["--hours", "0.01"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the example is built with the tests");
    // Close the reading end at once, as `| head -0` would.
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(output.status.code(), Some(0), "{stderr}");
}

#[test]
fn the_example_refuses_a_non_utf8_argument_with_status_2() {
    let output = Command::new(example_binary("chip_cell"))
        .arg(OsString::from_vec(vec![0xff]))
        .output()
        .expect("the example is built with the tests");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("is not valid UTF-8"), "{stderr}");
}

#[test]
fn the_example_draws_the_appendix_module_tree() {
    let output = Command::new(example_binary("chip_cell"))
        .args(["--hours", "0.01", "--tree"])
        .output()
        .expect("the example is built with the tests");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(0), "{stdout}");
    // LOAD_IT costarts its two children and asks each down the tree; the children hand the
    // card to each other across it, the chip robots share the feeder across lines, and
    // LOAD_IT sends its cycle times to GATE through FREQUENCY, across the tree.
    for line in [
        "├─ LOAD_IT  [2 vertical, 1 horizontal]",
        "FREQUENCY        GATE <- LOAD_IT  horizontal",
        "│  ├─ LOAD_CARD  [1 vertical, 1 horizontal]",
        "│  └─ SCREW_IN_CARD  [1 vertical, 1 horizontal]",
        "ASK_CHILD1       LOAD_IT <- LOAD_CARD  vertical",
        "CARD_IN_PLACE    LOAD_CARD <- SCREW_IN_CARD  horizontal",
        "SHARE_FEEDER     CHIP_IT <- CHIP_IT2  horizontal",
    ] {
        assert!(stdout.contains(line), "{line:?} in\n{stdout}");
    }
}

#[test]
fn the_example_records_and_draws_as_the_readme_says() {
    let dir = std::env::temp_dir().join(format!("imrs-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (mcap, svg) = (dir.join("cell.mcap"), dir.join("cell.svg"));
    let output = Command::new(example_binary("chip_cell"))
        .args(["--hours", "0.02", "--feeder", "appendix", "--record"])
        .arg(&mcap)
        .arg("--timeline")
        .arg(&svg)
        .output()
        .expect("the example is built with the tests");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("open it in Foxglove"), "{stderr}");
    let summary = imrs_record::read_summary(&mcap).unwrap();
    assert!(summary.indexed && summary.messages > 100, "{summary}");
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.contains("CHIP_IT2") && picture.contains("deadlock"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rust_log_shows_what_the_core_emits_and_nothing_without_it() {
    let run_with = |log: Option<&str>| {
        let mut command = Command::new(example_binary("chip_cell"));
        command.args(["--hours", "0.02", "--feeder", "appendix"]);
        match log {
            Some(filter) => command.env("RUST_LOG", filter),
            None => command.env_remove("RUST_LOG"),
        };
        let output = command
            .output()
            .expect("the example is built with the tests");
        assert_eq!(output.status.code(), Some(0));
        String::from_utf8_lossy(&output.stderr).into_owned()
    };
    let warned = run_with(Some("imrs=warn"));
    assert!(
        warned.contains(
            "WARN imrs: [27.420s] CHIP_IT2/CHIP_IT2: deadlock: CHIP_IT2 -[SHARE_FEEDER1]-> CHIP_IT"
        ),
        "{warned}"
    );
    assert!(!run_with(None).contains("imrs:"));
}
