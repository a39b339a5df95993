//! What an import or an export across processes refuses, by name: a module off the user
//! list, a type the other process does not share, a cell name that cannot name a service, a
//! port full of users (however many its restrictions admit, not iceoryx2's default), a port
//! that nobody exports, and a runtime without its I/O driver.

mod common;

use std::time::Duration;

use common::{Number, owner, within};
use imrs_ipc::{FromBytes, Imported, IpcError, Remote, ZeroCopySend, import};
use imrs_ports::{WireError, usage};
use imrs_testkit::unique_name;

/// A message the peer does not know.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Wide")]
struct Wide {
    value: u64,
    more: u64,
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_module_not_on_the_user_list_is_refused_by_name() {
    let cell = unique_name("unlisted");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let error = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "STRANGER",
    )
    .err()
    .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::NotOnUserList {
            port: "DOUBLE".into(),
            module: "STRANGER".into(),
        })
    );
    assert!(error.to_string().contains("STRANGER"), "{error}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_type_the_other_process_does_not_share_is_refused_naming_the_port() {
    let cell = unique_name("types");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let error =
        import::<Imported<Wide, Number, usage::Receive>, _>(&remote, "DOUBLE", "DOUBLER", "ASKER")
            .err()
            .expect("refused");
    assert!(
        matches!(&error, IpcError::TypeMismatch { port, .. } if port == "DOUBLE"),
        "{error:?}"
    );
}

#[test]
fn a_cell_name_that_cannot_name_a_service_is_refused_by_name() {
    let error = Remote::new("my cell/../x").unwrap_err();
    assert!(error.to_string().contains("my cell/../x"), "{error}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_port_full_of_users_refuses_one_more_process_with_its_capacity() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("full");
    // Room for one user, whoever it is.
    let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("SINGLE", "OWNER"));
    let remote = Remote::new(&cell).unwrap();
    let _exported = imrs_ipc::export(&remote, &port).unwrap();
    let _first =
        import::<Imported<Number, Number, usage::Receive>, _>(&remote, "SINGLE", "OWNER", "FIRST")
            .unwrap();
    let error =
        import::<Imported<Number, Number, usage::Receive>, _>(&remote, "SINGLE", "OWNER", "SECOND")
            .err()
            .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::TooManyUsers {
            port: "SINGLE".into(),
            module: "SECOND".into(),
            capacity: 1,
        })
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_port_admits_as_many_user_processes_as_its_restrictions_say_not_iceoryx2s_default() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("many");
    // Three times iceoryx2's default of 8 clients to a service.
    const USERS: usize = 24;
    let port: Port<Number, Number, usage::Receive, AnyUser, USERS> =
        Port::new(PortSpec::new("MANY", "OWNER"));
    let remote = Remote::new(&cell).unwrap();
    let _exported = imrs_ipc::export(&remote, &port).unwrap();
    let users: Vec<_> = (0..USERS)
        .map(|n| {
            let module = format!("USER_{n}");
            import::<Imported<Number, Number, usage::Receive>, _>(&remote, "MANY", "OWNER", &module)
                .unwrap_or_else(|error| panic!("{module}: {error}"))
        })
        .collect();
    // One more is refused by the port, naming it, as in one process.
    let error = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote,
        "MANY",
        "OWNER",
        "ONE_TOO_MANY",
    )
    .err()
    .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::TooManyUsers {
            port: "MANY".into(),
            module: "ONE_TOO_MANY".into(),
            capacity: USERS,
        })
    );
    // And every admitted user is served.
    let mut owner = port.owner().unwrap();
    let serve = tokio::spawn(async move {
        for _ in 0..USERS {
            let (n, reply) = owner.receive().await.unwrap();
            reply.reply(Number { value: n.value * 2 });
        }
    });
    for (n, imported) in users.iter().enumerate() {
        let mut end = imported.port().user_named(format!("USER_{n}")).unwrap();
        let value = n as u64;
        let doubled = within(10, end.send(Number { value })).await.unwrap();
        assert_eq!(doubled.value, 2 * value);
    }
    within(10, serve).await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn importing_a_port_that_nobody_exports_says_so_at_once() {
    let remote = Remote::new(&unique_name("nobody")).unwrap();
    let started = std::time::Instant::now();
    let error =
        import::<Imported<Number, Number, usage::Receive>, _>(&remote, "NOBODYS", "OWNER", "USER")
            .err()
            .expect("refused");
    assert_eq!(
        error,
        IpcError::NoOwner {
            port: "NOBODYS".into()
        }
    );
    // Not after the connect timeout: the port's services are not there at all.
    assert!(started.elapsed() < Duration::from_secs(2));
}

#[test]
fn a_runtime_without_its_io_driver_is_refused_by_name_not_by_a_panic() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    // The bridges wait on tokio's reactor: a runtime built without it cannot carry a port.
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .build()
        .unwrap();
    let cell = unique_name("no-io");
    runtime.block_on(async {
        let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
            Port::new(PortSpec::new("QUIET", "OWNER"));
        let error = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port)
            .err()
            .expect("refused");
        assert!(
            matches!(&error, IpcError::Transport { port, .. } if port == "QUIET"),
            "{error:?}"
        );
        assert!(error.to_string().contains("I/O driver"), "{error}");
    });
}
