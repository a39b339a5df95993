//! The load-time check: every problem at once, each naming its module and port.

use imrs_core::prelude::*;
use imrs_core::{CellError, ModuleDecl};
use imrs_ports::AnyUser;

fn cell() -> Cell {
    Cell::virtual_clock().0
}

fn declare_appendix_ports(cell: &Cell) {
    // LET_1_GO: owned by GATE, #USERS=1.
    let _: Port<(), i32, usage::Send> = cell.port(PortSpec::new("LET_1_GO", "GATE")).unwrap();
    // ASK_CHILD1: owned by LOAD_IT, USERLIST=(LOAD_CARD).
    let _: Port<(), (i32, u32), usage::Query> = cell
        .port(PortSpec::new("ASK_CHILD1", "LOAD_IT").user_list(["LOAD_CARD"]))
        .unwrap();
    // CARD_IN_PLACE: owned by LOAD_CARD, USAGE=SEND.
    let _: Port<(), i32, usage::Send, AnyUser, 2> = cell
        .port(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"))
        .unwrap();
    // FREQUENCY: owned by GATE, filtered by its task BOUNDED_BUFFER.
    let _: BoundedBufferPort<(i32, f64), AnyUser, 2> = cell
        .filtered_port(PortSpec::new("FREQUENCY", "GATE"), "BOUNDED_BUFFER")
        .unwrap();
}

fn decl(spec: ModuleSpec<()>) -> ModuleDecl {
    spec.declaration()
}

#[test]
fn a_correct_cell_passes() {
    let cell = cell();
    declare_appendix_ports(&cell);
    let modules = [
        decl(
            ModuleSpec::new("GATE", ())
                .order(["LET_1_GO.TIMEOUT", "GATE"])
                .filters("FREQUENCY", UsageKind::Receive),
        ),
        decl(
            ModuleSpec::new("LOAD_IT", ())
                .order(["ASK_CHILD1.TIMEOUT", "LOAD_IT"])
                .uses_named("FREQUENCY", UsageKind::Send),
        ),
        decl(ModuleSpec::new("LOAD_CARD", ()).uses_named("ASK_CHILD1", UsageKind::Response)),
        decl(ModuleSpec::new("SCREW_IN_CARD", ()).uses_named("CARD_IN_PLACE", UsageKind::Receive)),
        decl(ModuleSpec::new("RELEASER", ()).uses_named("LET_1_GO", UsageKind::Receive)),
    ];
    assert_eq!(cell.check(&modules), Ok(()));
}

#[test]
fn every_problem_is_reported_at_once_naming_module_and_port() {
    let cell = cell();
    declare_appendix_ports(&cell);
    let modules = [
        // GATE's order names a handler it does not have; LOAD_CARD, the owner of
        // CARD_IN_PLACE, is not among the modules.
        decl(
            ModuleSpec::new("GATE", ())
                .order(["LET_1_GO.TIMEOUT", "GATE", "PANIC_BUTTON.PRESSED"])
                .filters("FREQUENCY", UsageKind::Send),
        ),
        decl(ModuleSpec::new("LOAD_IT", ())),
        // Not on ASK_CHILD1's user list; and both ends of CARD_IN_PLACE say SEND.
        decl(
            ModuleSpec::new("SCREW_IN_CARD", ())
                .uses_named("ASK_CHILD1", UsageKind::Response)
                .uses_named("CARD_IN_PLACE", UsageKind::Send),
        ),
        // Three users for a port of two.
        decl(ModuleSpec::new("A", ()).uses_named("CARD_IN_PLACE", UsageKind::Receive)),
        decl(ModuleSpec::new("B", ()).uses_named("CARD_IN_PLACE", UsageKind::Receive)),
    ];
    let problems = cell.check(&modules).unwrap_err();
    let expected = [
        CellError::NoOwner {
            port: "CARD_IN_PLACE".into(),
            declared_owner: "LOAD_CARD".into(),
        },
        CellError::NotOnUserList {
            port: "ASK_CHILD1".into(),
            module: "SCREW_IN_CARD".into(),
        },
        CellError::UsageMismatch {
            port: "CARD_IN_PLACE".into(),
            module: "SCREW_IN_CARD".into(),
            owner: UsageKind::Send,
            user: UsageKind::Send,
        },
        CellError::TooManyUsers {
            port: "CARD_IN_PLACE".into(),
            capacity: 2,
            modules: vec!["SCREW_IN_CARD".into(), "A".into(), "B".into()],
        },
        CellError::FilterUsageMismatch {
            port: "FREQUENCY".into(),
            module: "GATE".into(),
            filter: UsageKind::Send,
            declared: UsageKind::Receive,
        },
        CellError::UnknownOrderName {
            module: "GATE".into(),
            name: "PANIC_BUTTON.PRESSED".into(),
        },
    ];
    for problem in &expected {
        assert!(
            problems.0.contains(problem),
            "missing {problem:?} in {problems:#?}"
        );
    }
    assert_eq!(problems.0.len(), expected.len(), "{problems:#?}");

    let report = problems.to_string();
    for line in [
        "6 wiring problem(s):",
        "port CARD_IN_PLACE has no owner: its owner LOAD_CARD is not among the modules",
        "module SCREW_IN_CARD is not on the user list of port ASK_CHILD1",
        "module SCREW_IN_CARD uses port CARD_IN_PLACE with USAGE=SEND, which does not complement USAGE=SEND",
        "port CARD_IN_PLACE allows 2 user(s), but 3 use it: SCREW_IN_CARD A B",
        "module GATE filters port FREQUENCY with USAGE=SEND, but the port is declared USAGE=RECEIVE",
        "the order of module GATE names PANIC_BUTTON.PRESSED, which is not a handler or an exception of it",
    ] {
        assert!(report.contains(line), "missing line {line:?} in:\n{report}");
    }
}

#[test]
fn two_modules_of_one_name_are_refused() {
    let cell = cell();
    let problems = cell
        .check(&[
            decl(ModuleSpec::new("GATE", ())),
            decl(ModuleSpec::new("GATE", ())),
        ])
        .unwrap_err();
    assert_eq!(
        problems.0,
        [CellError::DuplicateModule {
            module: "GATE".into()
        }]
    );
}

#[test]
fn a_port_owned_in_another_process_needs_no_owner_here_but_its_users_are_still_checked() {
    let cell = cell();
    // As a transport imports it: the owner, ARBITER, runs in another process.
    let imported =
        Port::<u32, (), usage::Receive>::new(PortSpec::new("ZONE", "ARBITER").user_list(["ROBOT"]));
    cell.declare_imported(&imported).unwrap();
    // A port of this process that nobody owns is still a problem.
    let _: Port<u32, (), usage::Receive> = cell.port(PortSpec::new("ORPHAN", "GHOST")).unwrap();
    let modules = [
        decl(ModuleSpec::new("ROBOT", ()).uses_named("ZONE", UsageKind::Send)),
        // Not on the imported port's user list: refused here, as in one process.
        decl(ModuleSpec::new("INTRUDER", ()).uses_named("ZONE", UsageKind::Send)),
    ];
    let problems = cell.check(&modules).unwrap_err().to_string();
    assert!(!problems.contains("port ZONE has no owner"), "{problems}");
    assert!(problems.contains("port ORPHAN has no owner"), "{problems}");
    assert!(problems.contains("INTRUDER"), "{problems}");
    assert!(!problems.contains("module ROBOT"), "{problems}");
}
