//! Wiring slips that the load-time check catches, each by name, all at once: an exception
//! handler for nothing the module raises, a response handler named after the wrong port, a
//! response end on a port the module never declared, an earlier failed attach, a port with
//! two user lists.

mod common;

use common::{at, paused_runtime, secs};

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_core::{CellError, TaskError};
use imrs_ports::{WireError, user_list};

type Status = Port<(), u32, usage::Query>;

#[test]
fn every_slip_is_reported_at_once_by_module_and_name() {
    let (cell, _clock) = Cell::virtual_clock();
    let status: Status = cell.port(PortSpec::new("B_STATUS", "WELD_CELL")).unwrap();
    let _torch_ready: Port<(), (), usage::Send> =
        cell.port(PortSpec::new("TORCH_READY", "WELDER_B")).unwrap();
    // An earlier attach by name that failed: the wrong message type.
    let wrong_type = cell.use_port::<u8, (), usage::Receive>("TORCH", "TORCH_READY");
    assert!(wrong_type.is_err());

    let welder = ModuleSpec::new("WELDER_B", 0u32)
        // A typo: TIMOUT. Nothing the module has raises it.
        .exception("TORCH_READY.TIMOUT", |_: Ctx<u32>, _| async {})
        // A response handler its order leaves out (the module has no order at all). A
        // handler named after another port than it answers cannot be written: its name is
        // made from the port.
        .respond(&status.handler("STATUS"), |seams: &u32, ()| *seams)
        .task("WELDER_B", |_| async { Ok(()) });
    let gas_monitor = ModuleSpec::new("GAS_MONITOR", ())
        .order(["GAS.LOW", "MONITOR.FAILED", "GAS_MONITOR"])
        .raises(["GAS.LOW"])
        .exception("GAS.LOW", |_: Ctx<()>, _| async {})
        .exception("MONITOR.FAILED", |_: Ctx<()>, _| async {})
        .task("MONITOR", |_| async { Ok(()) });
    let weld_cell = ModuleSpec::new("WELD_CELL", ());

    let problems = cell
        .check(&[
            welder.declaration(),
            gas_monitor.declaration(),
            weld_cell.declaration(),
        ])
        .unwrap_err()
        .0;
    assert_eq!(
        problems,
        [
            CellError::Wire(WireError::TypeMismatch {
                port: "TORCH_READY".into(),
                module: "TORCH".into(),
                declared: "() -> ()".into(),
                used: "u8 -> ()".into(),
            }),
            CellError::Unranked {
                module: "WELDER_B".into(),
                handler: "B_STATUS.STATUS".into(),
            },
            CellError::Unranked {
                module: "WELDER_B".into(),
                handler: "TORCH_READY.TIMOUT".into(),
            },
            CellError::UnknownException {
                module: "WELDER_B".into(),
                exception: "TORCH_READY.TIMOUT".into(),
            },
        ],
        "{problems:#?}"
    );
    let text = imrs_core::CellErrors(problems).to_string();
    assert!(
        text.contains(
            "module WELDER_B handles exception TORCH_READY.TIMOUT, which it cannot raise"
        ),
        "{text}"
    );
    assert!(
        text.contains("module WELDER_B has a handler B_STATUS.STATUS that its order does not rank"),
        "{text}"
    );
}

user_list!(Welders = [WelderB];);
struct WelderB;
impl Named for WelderB {
    const NAME: &'static str = "WELDER_B";
}

#[test]
fn a_port_with_a_typed_and_a_named_user_list_is_refused_everywhere() {
    let (cell, _clock) = Cell::virtual_clock();
    let status = Port::<(), u32, usage::Query, Welders>::new(
        PortSpec::new("B_STATUS", "WELD_CELL")
            .user_list(["WELDER_A"])
            .clock(cell.clock().clone()),
    );
    let refused = WireError::TwoUserLists {
        port: "B_STATUS".into(),
    };
    assert_eq!(cell.declare(&status), Err(refused.clone()));
    assert_eq!(status.owner().unwrap_err(), refused);
    assert_eq!(
        status.answer("WELDER_A", |_: &(), ()| 0).unwrap_err(),
        refused
    );
    assert_eq!(
        refused.to_string(),
        "port B_STATUS is declared with a typed user list and a named one: keep one"
    );
    assert_eq!(
        cell.check(&[]).unwrap_err().0,
        [CellError::Wire(refused)],
        "the check remembers it"
    );
}

#[test]
fn a_restart_by_policy_is_not_an_unhandled_failure() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let module = ModuleSpec::new("GAS", ()).task_with_policy(
            "GAS_MONITOR",
            RestartPolicy::restart(2, secs(1)),
            |_| async { Err::<(), TaskError>("sensor glitch".into()) },
        );
        cell.start(module).unwrap();
        drive(&clock, at(10)).await;
        let events = cell.events().snapshot();
        let unhandled: Vec<_> = events
            .iter()
            .filter(|event| matches!(event.kind, EventKind::ExceptionUnhandled { .. }))
            .map(ToString::to_string)
            .collect();
        // Two failures restarted by the policy, then the third, which nothing handles.
        let restarts = events
            .iter()
            .filter(|event| matches!(event.kind, EventKind::TaskRestarted { .. }))
            .count();
        assert_eq!(restarts, 2);
        assert_eq!(unhandled.len(), 1, "{unhandled:?}");
    });
}
