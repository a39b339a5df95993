//! The chip cell across three processes (`chip_cell --processes`), run as an operator runs
//! it: the world's process reports as a single process does, a line's process that dies is
//! started again while the other line goes on (or, past its restarts or under a policy the
//! world does not restart a line under, fails the run by name without hanging it), and a
//! world that dies takes its lines with it.
//!
//! These run on the wall clock, sped up: time does not cross processes virtually. So each
//! cell runs alone (a second cell's processes would take the processors this one's timing
//! counts on), and at a speed that leaves its shortest timeout wall time to spare: LET_1_GO
//! gives RELEASE 2 s to let a pallet go, and the gate takes 0.3 s of them, which at ×60
//! leaves 28 ms of wall time for the round trip to the world and back; at ×20, 85 ms, and
//! at ×10, 170 ms.

use std::process::{Child, Command, Output, Stdio};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use imrs_testkit::example_binary;

/// The processes `pid` started, as Linux lists them.
fn children_of(pid: u32) -> Vec<u32> {
    let list = std::fs::read_to_string(format!("/proc/{pid}/task/{pid}/children"));
    list.unwrap_or_default()
        .split_whitespace()
        .filter_map(|child| child.parse().ok())
        .collect()
}

fn alive(pid: u32) -> bool {
    // A zombie has ended: only its parent has not read its status yet.
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
        !stat
            .rsplit(')')
            .next()
            .unwrap_or("")
            .trim_start()
            .starts_with('Z')
    })
}

/// Kills `pid` with SIGKILL, and waits until it has died: `kill` returns once the signal
/// is sent, before the process is gone.
fn kill_9(pid: u32) {
    let killed = Command::new("kill").args(["-9", &pid.to_string()]).status();
    assert!(killed.is_ok_and(|status| status.success()), "kill -9 {pid}");
    assert!(
        within(Duration::from_secs(5), || !alive(pid)),
        "{pid} outlived SIGKILL"
    );
}

/// Waits (polling, bounded) until `condition` holds; whether it did.
fn within(limit: Duration, mut condition: impl FnMut() -> bool) -> bool {
    let start = Instant::now();
    while start.elapsed() < limit {
        if condition() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    condition()
}

/// Held by the cell that runs now: one at a time.
static ONE_CELL: Mutex<()> = Mutex::new(());

/// The world, started: killed, with its lines, if the test fails before it ends.
struct World {
    child: Option<Child>,
    pid: u32,
    /// Its status was read: its pid may now name another process.
    reaped: bool,
    /// Dropped last, once the world and its lines are gone.
    _alone: MutexGuard<'static, ()>,
}

impl World {
    fn start(args: &[&str]) -> Self {
        // A test that failed holding the lock left no cell behind: `Drop` killed it.
        let alone = ONE_CELL.lock().unwrap_or_else(PoisonError::into_inner);
        let child = Command::new(example_binary("chip_cell"))
            .arg("--processes")
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the example is built with the tests");
        Self {
            pid: child.id(),
            child: Some(child),
            reaped: false,
            _alone: alone,
        }
    }

    fn pid(&self) -> u32 {
        self.pid
    }

    /// Its two lines' processes, once both are running.
    fn lines(&self) -> Vec<u32> {
        let mut lines = Vec::new();
        let started = within(Duration::from_secs(30), || {
            lines = children_of(self.pid());
            lines.len() == 2
        });
        assert!(
            started,
            "the world did not start two line processes: {lines:?}"
        );
        lines
    }

    /// Its output once it has ended, read as it comes (so that a full pipe never holds it
    /// up); the test fails if it has not ended within `limit`.
    fn finish(mut self, limit: Duration) -> Output {
        let child = self.child.take().expect("not finished yet");
        let (output, ended) = std::sync::mpsc::channel();
        std::thread::spawn(move || output.send(child.wait_with_output()));
        let output = ended
            .recv_timeout(limit)
            .unwrap_or_else(|_| panic!("the world did not end within {limit:?}"));
        self.reaped = true;
        output.unwrap()
    }

    /// Its report, once it has ended within `limit` with status 0.
    fn report(self, limit: Duration) -> String {
        let output = self.finish(limit);
        let (report, errors) = (
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr),
        );
        assert_eq!(output.status.code(), Some(0), "{report}\n{errors}");
        report.into_owned()
    }
}

impl Drop for World {
    fn drop(&mut self) {
        // An ended world ended its lines (it kills any that outlive its patience), and its
        // pid may now name another process: nothing is left to clean.
        if self.reaped {
            return;
        }
        // Whatever is left of the run: the lines, and the world if `finish` gave up on it.
        let mut left = children_of(self.pid);
        match &mut self.child {
            Some(child) => {
                let _ = child.kill();
                let _ = child.wait();
            }
            // `finish` gave up on it: its thread holds the child, so it is killed by pid.
            None => left.push(self.pid),
        }
        for pid in left {
            let _ = Command::new("kill").args(["-9", &pid.to_string()]).status();
        }
    }
}

/// A row of the report: its two columns, line A and line B.
fn row<'a>(report: &'a str, what: &str) -> (&'a str, &'a str) {
    let line = report
        .lines()
        .find(|line| line.trim_start().starts_with(what))
        .unwrap_or_else(|| panic!("no row {what:?} in:\n{report}"));
    let mut columns = line.split_whitespace().rev();
    let b = columns.next().unwrap();
    let a = columns.next().unwrap();
    (a, b)
}

/// The zone requests and refusals of each line, as the report counts them.
fn zone_requests(report: &str) -> [(u32, u32); 2] {
    let (a, b) = row(report, "zone requests / refused");
    [a, b].map(|asked| {
        let (requests, refused) = asked.split_once('/').unwrap();
        (requests.parse().unwrap(), refused.parse().unwrap())
    })
}

#[test]
fn the_cell_across_three_processes_reports_as_a_single_process_does() {
    // Six simulated minutes at twenty times the wall clock.
    let world = World::start(&["--hours", "0.1", "--speed", "20"]);
    let lines = world.lines();
    assert!(lines.iter().all(|line| *line != world.pid()));
    let report = world.report(Duration::from_secs(120));
    assert!(
        report.contains("processes: world (simulation, WORLD, FEEDER_MONITOR), line A, line B"),
        "{report}"
    );
    // The simulation ran in the world; the lines' modules drove it from their processes.
    for what in [
        "pallets released",
        "pallets completed",
        "feeder zone entries (rapier)",
    ] {
        let (a, b) = row(&report, what);
        let (a, b): (u32, u32) = (a.parse().unwrap(), b.parse().unwrap());
        assert!(a > 0 && b > 0, "{what}: {a} and {b}\n{report}");
    }
    // The chip robots' waits for the zone were counted in the lines' processes and came
    // back with their figures.
    for (requests, _) in zone_requests(&report) {
        assert!(requests > 0, "{requests}\n{report}");
    }
    assert!(report.contains("[ok] no two robots in the feeder zone together (rapier)"));
    assert!(report.contains("[ok] no two arms touching (rapier)"));
    assert!(!report.contains("[FAILED]"), "{report}");
    // How late each process's timer woke was measured, and the worst is named: whether the
    // machine kept up is the machine's, not the cell's, so either verdict will do here.
    let kept_up = report
        .lines()
        .find(|line| {
            line.starts_with("kept up with x 20: ") || line.starts_with("FELL BEHIND x 20: ")
        })
        .unwrap_or_else(|| panic!("no line on keeping up in\n{report}"));
    assert!(
        ["world", "line A", "line B"]
            .iter()
            .any(|process| kept_up.contains(&format!(" simulated), in {process}"))),
        "{kept_up}"
    );
    // The lines ended with the world.
    for line in lines {
        assert!(
            within(Duration::from_secs(5), || !alive(line)),
            "line {line} lives on"
        );
    }
}

#[test]
fn under_the_appendixs_policy_each_chip_robot_asks_its_twin_in_the_other_process() {
    let world = World::start(&["--feeder", "appendix", "--hours", "0.1", "--speed", "20"]);
    let report = world.report(Duration::from_secs(120));
    // No arbiter in the world: the lines ask each other.
    assert!(
        report.contains("processes: world (simulation, WORLD), line A, line B"),
        "{report}"
    );
    // A chip robot enters the zone only once its twin, in the other process, answered
    // CLEAR from its response handler: cards done on both lines are answers that crossed.
    let (a, b) = row(&report, "pallets completed");
    let (a, b): (u32, u32) = (a.parse().unwrap(), b.parse().unwrap());
    assert!(a > 0 && b > 0, "{a} and {b}\n{report}");
    for (requests, refused) in zone_requests(&report) {
        assert!(requests > refused, "{requests}/{refused}\n{report}");
    }
    assert!(report.contains("[ok] no two robots in the feeder zone together (rapier)"));
    assert!(!report.contains("[FAILED]"), "{report}");
}

#[test]
fn under_the_coordinator_each_chip_robot_reserves_its_sweep_in_the_worlds_process() {
    let world = World::start(&["--feeder", "coordinator", "--hours", "0.1", "--speed", "20"]);
    let report = world.report(Duration::from_secs(120));
    assert!(
        report.contains("processes: world (simulation, WORLD, FEEDER_COORDINATOR), line A, line B"),
        "{report}"
    );
    // Each step's sweep was computed by the world's simulation, for a chip robot in a line's
    // process, and reserved with the coordinator back in the world: cards done on both
    // lines are reservations granted across processes.
    let (a, b) = row(&report, "pallets completed");
    let (a, b): (u32, u32) = (a.parse().unwrap(), b.parse().unwrap());
    assert!(a > 0 && b > 0, "{a} and {b}\n{report}");
    for (requests, refused) in zone_requests(&report) {
        assert!(
            requests > 0 && refused == 0,
            "{requests}/{refused}\n{report}"
        );
    }
    // What the reservations kept apart, rapier measured.
    assert!(
        report.contains("[ok] no two arms touching (rapier)"),
        "{report}"
    );
    assert!(!report.contains("[FAILED]"), "{report}");
}

#[test]
fn faults_reach_the_process_they_belong_to_and_their_alarms_come_back() {
    // RELEASE dies in line A's process; line B's chip robot faults in the world's
    // simulation, and the fault reaches CHIP_IT2 across processes as the device's error.
    let world = World::start(&[
        "--hours",
        "0.05",
        "--speed",
        "10",
        "--fault",
        "release:A@60s",
        "--fault",
        "robot:B@90s",
    ]);
    let report = world.report(Duration::from_secs(120));
    assert!(
        report.contains("faults injected: release:A@60s, robot:B@90s"),
        "{report}"
    );
    let restarts = report
        .lines()
        .find_map(|line| line.strip_prefix("restarts: "))
        .unwrap_or_else(|| panic!("no restarts in\n{report}"));
    // The whole report on failure: its last lines say whether the machine kept up.
    assert!(restarts.starts_with("1 "), "{restarts}\n{report}");
    assert!(restarts.contains("robot fault 1"), "{restarts}\n{report}");
    assert!(restarts.contains("task failed 1"), "{restarts}\n{report}");
}

/// The living process of `line` ("A" or "B") among the world's children, if any.
fn line_process(world: u32, line: &str) -> Option<u32> {
    children_of(world).into_iter().find(|pid| {
        let cmdline = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap_or_default();
        let args: Vec<&[u8]> = cmdline.split(|b| *b == 0).collect();
        alive(*pid)
            && args
                .windows(2)
                .any(|pair| pair[0] == b"--line-process" && pair[1] == line.as_bytes())
    })
}

/// `line`'s process among `world`'s children once it is up, waited for within `limit`.
fn line_up(world: u32, line: &str, limit: Duration) -> Option<u32> {
    let mut found = None;
    within(limit, || {
        found = line_process(world, line);
        found.is_some()
    });
    found
}

/// `report` shows line A's outage (its `what`: "process died", "host was cut off") and its
/// next run back before the end; both lines completed cards, and no invariant failed.
fn line_a_came_back(report: &str, what: &str) {
    let outage = report
        .lines()
        .find_map(|line| line.strip_prefix("outage: "))
        .unwrap_or_else(|| panic!("no outage in\n{report}"));
    assert!(
        outage.starts_with(&format!("line A's {what} at "))
            && outage.contains("started again (run 1), back "),
        "{outage}"
    );
    let (a, b) = row(report, "pallets completed");
    let (a, b): (u32, u32) = (a.parse().unwrap(), b.parse().unwrap());
    assert!(a > 0 && b > 0, "{a} and {b}\n{report}");
    assert!(!report.contains("[FAILED]"), "{report}");
}

#[test]
fn a_line_killed_mid_run_is_started_again_and_the_other_goes_on() {
    // Six simulated minutes at twenty times the wall clock: 18 s.
    let world = World::start(&["--hours", "0.1", "--speed", "20"]);
    let lines = world.lines();
    let (line_a, line_b) = (
        line_process(world.pid(), "A").unwrap(),
        line_process(world.pid(), "B").unwrap(),
    );
    assert_eq!(lines.len(), 2);
    // Let the run get going (about a simulated minute), then kill line A.
    std::thread::sleep(Duration::from_secs(3));
    kill_9(line_a);
    // Line A's next run is started; line B's process is the same one all along.
    let restarted = line_up(world.pid(), "A", Duration::from_secs(10));
    assert!(restarted.is_some(), "line A was not started again");
    assert_ne!(restarted, Some(line_a));
    std::thread::sleep(Duration::from_secs(8));
    assert!(alive(line_b), "line B stopped");
    assert_eq!(line_process(world.pid(), "B"), Some(line_b));
    let report = world.report(Duration::from_secs(120));
    // Both lines completed cards, before and after, and every invariant held: no pallet
    // lost (those the dead line held are counted as scrapped), nothing in the zone
    // together, no arms touching.
    line_a_came_back(&report, "process died");
    assert_eq!(report.matches("outage: ").count(), 1, "{report}");
    assert!(report.contains("[ok] no pallet lost"), "{report}");
}

/// Six simulated minutes under feeder policy `policy`, line A killed about a simulated
/// minute in: line B's process runs on, line A comes back, no pallet is lost and no arms
/// touch. The report.
fn line_a_killed_under(policy: &str) -> String {
    let world = World::start(&["--feeder", policy, "--hours", "0.1", "--speed", "20"]);
    world.lines();
    let line_b = line_process(world.pid(), "B").unwrap();
    std::thread::sleep(Duration::from_secs(3));
    kill_9(line_process(world.pid(), "A").unwrap());
    std::thread::sleep(Duration::from_secs(8));
    assert_eq!(
        line_process(world.pid(), "B"),
        Some(line_b),
        "line B stopped"
    );
    let report = world.report(Duration::from_secs(120));
    line_a_came_back(&report, "process died");
    assert!(report.contains("[ok] no pallet lost"), "{report}");
    assert!(
        report.contains("[ok] no two arms touching (rapier)"),
        "{report}"
    );
    report
}

#[test]
fn under_the_coordinator_a_line_killed_is_started_again_and_the_other_goes_on() {
    // What the dead line's chip robot held or asked for of the coordinator is let go: the
    // other line's reservations are granted on, and the next run's too.
    let report = line_a_killed_under("coordinator");
    assert!(report.contains("timeouts: none"), "{report}");
    for (requests, refused) in zone_requests(&report) {
        assert!(
            requests > 0 && refused == 0,
            "{requests}/{refused}\n{report}"
        );
    }
}

#[test]
#[cfg_attr(
    not(feature = "zenoh"),
    ignore = "needs the `zenoh` feature: cargo test --workspace --all-features"
)]
fn over_zenoh_each_line_is_a_host_of_its_own_and_one_killed_is_started_again() {
    // Six simulated minutes at twenty times the wall clock, the lines' processes each in a
    // network namespace of its own (as root; else on loopback, said loudly).
    let world = World::start(&["--transport", "zenoh", "--hours", "0.1", "--speed", "20"]);
    world.lines();
    let line_b = line_process(world.pid(), "B").unwrap();
    std::thread::sleep(Duration::from_secs(3));
    // Line A's process as the world runs it now: a run started again meanwhile (its host
    // seen gone under load) is found once it is up, and the report names that outage.
    let line_a = line_up(world.pid(), "A", Duration::from_secs(30))
        .expect("no process of line A among the world's children");
    kill_9(line_a);
    let report = world.report(Duration::from_secs(120));
    let apart = report.contains(
        "line A, line B over zenoh, each a host of its own (a network namespace, joined to \
         the world's by a veth link)",
    );
    let loopback = report.contains("line A, line B over zenoh, ON LOOPBACK, not hosts apart");
    assert!(apart || loopback, "{report}");
    if loopback {
        eprintln!("\n*** this run's hosts were on loopback, not apart: see the report ***\n");
    }
    assert!(!alive(line_b), "line B outlived the run");
    // The restarted line worked again: its device calls were served (no LET_1_GO went
    // unanswered), and both lines completed cards.
    line_a_came_back(&report, "process died");
    assert!(report.contains("timeouts: none"), "{report}");
}

#[test]
#[cfg_attr(
    not(feature = "zenoh"),
    ignore = "needs the `zenoh` feature: cargo test --workspace --all-features"
)]
fn over_zenoh_a_line_whose_host_is_cut_off_and_healed_is_started_again() {
    let world = World::start(&["--transport", "zenoh", "--hours", "0.1", "--speed", "20"]);
    world.lines();
    // Line A's namespace's link, on the world's side (`imrs_zenoh::netns`).
    let link = format!("imrso{}x0", world.pid() % 100_000);
    let set = |state: &str| {
        Command::new("ip")
            .args(["link", "set", &link, state])
            .status()
            .is_ok_and(|status| status.success())
    };
    std::thread::sleep(Duration::from_secs(3));
    if !set("down") {
        // No namespaces here (not root, no `ip`): the hosts are on loopback and cannot be cut.
        eprintln!(
            "\n*** LOOPBACK: line A's host cannot be cut off here; the cut is not tried ***\n"
        );
        let report = world.report(Duration::from_secs(120));
        assert!(report.contains("ON LOOPBACK, not hosts apart"), "{report}");
        return;
    }
    // Longer than the hosts' lease (2 s): the world sees line A's host gone.
    std::thread::sleep(Duration::from_secs(4));
    assert!(set("up"), "the link set up again");
    let report = world.report(Duration::from_secs(120));
    line_a_came_back(&report, "host was cut off");
}

#[test]
fn a_line_that_keeps_dying_fails_the_run_past_its_restarts() {
    // An hour at ten times the wall clock: six minutes, unless the restarts run out.
    let world = World::start(&["--hours", "1", "--speed", "10"]);
    world.lines();
    // Line A is killed four times, each time once its next run is up.
    let mut killed = None;
    for _ in 0..4 {
        let mut line_a = None;
        assert!(
            within(Duration::from_secs(10), || {
                line_a = line_process(world.pid(), "A").filter(|pid| Some(*pid) != killed);
                line_a.is_some()
            }),
            "line A was not started again"
        );
        std::thread::sleep(Duration::from_millis(500));
        kill_9(line_a.unwrap());
        killed = line_a;
    }
    let output = world.finish(Duration::from_secs(30));
    let errors = String::from_utf8_lossy(&output.stderr);
    assert_ne!(output.status.code(), Some(0), "{errors}");
    assert!(
        errors.contains("line A: died 4 times: the world starts a line again at most 3 times"),
        "{errors}"
    );
}

#[test]
fn under_the_appendixs_policy_a_line_killed_is_started_again_and_its_twin_waits_for_it() {
    // The lines ask each other: while line A is down, CHIP_IT2 has no permission to enter
    // the zone, and asks again each second until A's next run answers.
    line_a_killed_under("appendix");
}

#[test]
fn a_world_killed_mid_run_takes_its_lines_with_it() {
    let world = World::start(&["--hours", "1", "--speed", "10"]);
    let lines = world.lines();
    std::thread::sleep(Duration::from_secs(3));
    kill_9(world.pid());
    for line in lines {
        assert!(
            within(Duration::from_secs(10), || !alive(line)),
            "line {line} outlived its world"
        );
    }
}

#[test]
fn what_does_not_cross_processes_is_refused_by_name_before_anything_starts() {
    for (flags, named) in [
        (&["--record", "x.mcap"][..], "--record"),
        (&["--tree"][..], "--tree"),
        (&["--realtime"][..], "--realtime"),
        #[cfg(feature = "zenoh")]
        (
            &["--transport", "zenoh", "--feeder", "appendix"][..],
            "--transport zenoh with --feeder appendix",
        ),
    ] {
        let output = Command::new(example_binary("chip_cell"))
            .arg("--processes")
            .args(flags)
            .output()
            .unwrap();
        let errors = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{flags:?}: {errors}");
        assert!(errors.contains("not with --processes"), "{errors}");
        assert!(errors.contains(named), "{errors}");
    }
    // Refused before anything starts: no recording was begun.
    assert!(!std::path::Path::new("x.mcap").exists());
    // A speed-up or a transport without processes, or a speed-up that means nothing, is a
    // mistake of the flags.
    for flags in [
        &["--speed", "10"][..],
        &["--transport", "zenoh"][..],
        &["--processes", "--speed", "0.5"][..],
    ] {
        let output = Command::new(example_binary("chip_cell"))
            .args(flags)
            .output()
            .unwrap();
        let errors = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{flags:?}: {errors}");
        assert!(
            errors.contains("--speed") || errors.contains("--processes"),
            "{errors}"
        );
    }
}
