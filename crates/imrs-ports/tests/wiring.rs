//! Wiring errors (the seed's load-time errors): each names its port and module.

use imrs_ports::{AnyUser, Port, PortSpec, UsageKind, WireError, Wiring, usage};

#[test]
fn too_many_users_is_refused_naming_port_and_module() {
    // READY_TO_CHIP: #USERS=1.
    let port =
        Port::<(), (), usage::Receive, AnyUser, 1>::new(PortSpec::new("READY_TO_CHIP", "CHIP_IT"));
    let first = port.user_named("FREEZE_CARD").unwrap();
    let second = port.user_named("FREEZE_CARD_COPY").unwrap_err();
    assert_eq!(
        second,
        WireError::TooManyUsers {
            port: "READY_TO_CHIP".into(),
            module: "FREEZE_CARD_COPY".into(),
            capacity: 1
        }
    );
    assert_eq!(
        second.to_string(),
        "module FREEZE_CARD_COPY cannot use port READY_TO_CHIP: it allows 1 active user(s) and all are attached"
    );
    // A dead driver's slot is freed: a new copy attaches (the Appendix's note 3).
    drop(first);
    port.user_named("FREEZE_CARD_COPY").unwrap();
}

#[test]
fn a_user_not_on_the_list_is_refused() {
    let port = Port::<u8, i32, usage::Query>::new(
        PortSpec::new("SHARE_FEEDER", "CHIP_IT").user_list(["CHIP_IT2"]),
    );
    let refused = port.answer("LOAD_IT", |_: &(), _: u8| 0).unwrap_err();
    assert_eq!(
        refused,
        WireError::NotOnUserList {
            port: "SHARE_FEEDER".into(),
            module: "LOAD_IT".into()
        }
    );
    assert_eq!(
        refused.to_string(),
        "module LOAD_IT is not on the user list of port SHARE_FEEDER"
    );
    port.answer("CHIP_IT2", |_: &(), _: u8| 1).unwrap();
}

#[test]
fn a_second_owner_is_refused() {
    let port = Port::<(), (), usage::Send>::new(PortSpec::new("LET_1_GO", "GATE"));
    let _gate = port.owner().unwrap();
    assert_eq!(
        port.owner().unwrap_err(),
        WireError::OwnerTaken {
            port: "LET_1_GO".into(),
            module: "GATE".into()
        }
    );
}

#[test]
fn wiring_by_name_checks_usage_types_and_lists_every_problem() {
    let mut wiring = Wiring::new();
    let card_in_place = Port::<(), i32, usage::Send>::new(
        PortSpec::new("CARD_IN_PLACE", "LOAD_CARD").user_list(["SCREW_IN_CARD"]),
    );
    wiring.declare(&card_in_place).unwrap();

    // Both ends declared SEND: correct locally, wrong globally (the seed's footnote 4).
    let usage = wiring
        .use_port::<(), i32, usage::Send>("SCREW_IN_CARD", "CARD_IN_PLACE")
        .unwrap_err();
    assert_eq!(
        usage,
        WireError::UsageMismatch {
            port: "CARD_IN_PLACE".into(),
            module: "SCREW_IN_CARD".into(),
            owner: UsageKind::Send,
            user: UsageKind::Send
        }
    );
    let types = wiring
        .use_port::<(), u8, usage::Receive>("SCREW_IN_CARD", "CARD_IN_PLACE")
        .unwrap_err();
    assert!(
        matches!(&types, WireError::TypeMismatch { port, module, .. } if port == "CARD_IN_PLACE" && module == "SCREW_IN_CARD"),
        "{types:?}"
    );
    let unknown = wiring
        .use_port::<(), i32, usage::Receive>("SCREW_IN_CARD", "CARD_IN_PLAC")
        .unwrap_err();
    assert_eq!(
        unknown,
        WireError::UnknownPort {
            port: "CARD_IN_PLAC".into(),
            module: "SCREW_IN_CARD".into()
        }
    );
    let listed = wiring
        .use_port::<(), i32, usage::Receive>("LOAD_IT", "CARD_IN_PLACE")
        .unwrap_err();
    assert!(matches!(listed, WireError::NotOnUserList { .. }));
    assert_eq!(
        wiring.declare(&card_in_place.clone()).unwrap_err(),
        WireError::DuplicatePort {
            port: "CARD_IN_PLACE".into(),
            module: "LOAD_CARD".into()
        }
    );

    // A correct use still works after the refusals, and the report lists all five problems.
    let _screw_in_card = wiring
        .use_port::<(), i32, usage::Receive>("SCREW_IN_CARD", "CARD_IN_PLACE")
        .unwrap();
    let problems = wiring.check().unwrap_err();
    assert_eq!(
        problems.0,
        [usage, types, unknown, listed, problems.0[4].clone()]
    );
    let report = problems.to_string();
    assert!(report.starts_with("5 wiring problem(s):"), "{report}");
    assert!(report.contains("USAGE=SEND, which does not complement the owner's USAGE=SEND"));
}

#[test]
fn a_wired_end_talks_to_the_declared_owner() {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let mut wiring = Wiring::new();
        let port = Port::<(), i32, usage::Send>::new(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"));
        wiring.declare(&port).unwrap();
        let mut load_card = port.owner().unwrap();
        let mut screw_in_card = wiring
            .use_port::<(), i32, usage::Receive>("SCREW_IN_CARD", "CARD_IN_PLACE")
            .unwrap();
        let screwing = tokio::spawn(async move {
            let ((), reply) = screw_in_card.receive().await.unwrap();
            reply.reply(0);
        });
        assert_eq!(load_card.send(()).await.unwrap(), 0);
        screwing.await.unwrap();
        assert!(wiring.check().is_ok());
    });
}
