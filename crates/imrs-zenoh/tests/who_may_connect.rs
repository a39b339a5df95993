//! Who may connect: hosts prove who they are with certificates made here, signed by the
//! cell's authority, over mutual TLS; on each port's keys, zenoh's access control lets in
//! only the host of its owner and the hosts of the modules on its user list. A host without
//! a certificate, and one with a valid certificate that is not admitted, get nothing — not
//! even under a module name on the list — and cannot pass for the owner; an admitted host
//! cannot pass for another host's module.

mod common;

use std::path::PathBuf;

use common::{PROMPTLY, within};
use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_zenoh::{Host, Imported, TlsFiles, ZenohError, export, import};
use rcgen::{BasicConstraints, CertificateParams, DnType, IsCa, Issuer, KeyPair};

/// A cell's certificate authority, and the files of the hosts it signs, in a directory of
/// this test's own.
struct Authority {
    dir: PathBuf,
    issuer: Issuer<'static, KeyPair>,
}

impl Authority {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("imrs-tls-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let key = KeyPair::generate().unwrap();
        let mut params = CertificateParams::new(Vec::<String>::new()).unwrap();
        params.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
        params
            .distinguished_name
            .push(DnType::CommonName, "the cell's authority");
        let certificate = params.self_signed(&key).unwrap();
        std::fs::write(dir.join("authority.pem"), certificate.pem()).unwrap();
        Self {
            dir,
            issuer: Issuer::new(params, key),
        }
    }

    /// The files of host `name`: its certificate (common name `name`) and key.
    fn host(&self, name: &str) -> TlsFiles {
        let key = KeyPair::generate().unwrap();
        let mut params = CertificateParams::new(vec!["localhost".to_owned()]).unwrap();
        params.distinguished_name.push(DnType::CommonName, name);
        let certificate = params.signed_by(&key, &self.issuer).unwrap();
        let (cert, key_file) = (
            self.path(&format!("{name}.pem")),
            self.path(&format!("{name}.key")),
        );
        std::fs::write(&cert, certificate.pem()).unwrap();
        std::fs::write(&key_file, key.serialize_pem()).unwrap();
        TlsFiles {
            authority: self.path("authority.pem"),
            certificate: cert,
            key: key_file,
        }
    }

    fn path(&self, file: &str) -> PathBuf {
        self.dir.join(file)
    }
}

impl Drop for Authority {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A TLS endpoint on loopback that nothing listens on now.
fn tls_endpoint() -> String {
    imrs_testkit::free_endpoint().replacen("tcp/", "tls/", 1)
}

/// GRIP's users, each with its host.
const GRIP_USERS: [(&str, &str); 2] = [("ROBOT", "robot-host"), ("PANEL", "panel-host")];

/// A host of the cell with `files`, admitting GRIP as the wiring says, listening or
/// connecting on `endpoint`.
async fn host(files: TlsFiles, endpoint: &str, listens: bool) -> Host {
    let builder = Host::builder("tls_cell")
        .tls(files)
        .admit("GRIP", "gripper-host", GRIP_USERS);
    let builder = if listens {
        builder.listen(endpoint)
    } else {
        builder.connect(endpoint)
    };
    builder.open().await.unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn only_admitted_hosts_reach_a_port_and_none_passes_for_its_owner() {
    let authority = Authority::new("admit");
    let endpoint = tls_endpoint();
    let robot_host = host(authority.host("robot-host"), &endpoint, true).await;

    // A host with a valid certificate that is not admitted claims GRIP, owned by GRIPPER,
    // before the gripper's host is up: its answers are the opposite of the gripper's.
    let intruder_host = Host::builder("tls_cell")
        .tls(authority.host("intruder-host"))
        .connect(&endpoint)
        .open()
        .await
        .unwrap();
    let fake: Port<f32, bool, usage::Receive, AnyUser, 2> =
        Port::new(PortSpec::new("GRIP", "GRIPPER"));
    let fake_export = export(&intruder_host, &fake).await.unwrap();
    let mut faker = fake.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((width, reply)) = faker.receive().await {
            reply.reply(width >= 0.05);
        }
    });
    // The robot's host hears nothing of it.
    let claimed =
        import::<Imported<f32, bool, usage::Receive>>(&robot_host, "GRIP", "GRIPPER", "ROBOT")
            .await
            .unwrap_err();
    assert_eq!(
        claimed,
        ZenohError::NoOwner {
            port: "GRIP".into()
        }
    );
    drop(fake_export);

    // The gripper's host comes up: the robot is served by it, and by it alone.
    // The gripper's host connects to the robot's, and listens for hosts of its own.
    let gripper_endpoint = tls_endpoint();
    let gripper_host = Host::builder("tls_cell")
        .tls(authority.host("gripper-host"))
        .admit("GRIP", "gripper-host", GRIP_USERS)
        .connect(&endpoint)
        .listen(&gripper_endpoint)
        .open()
        .await
        .unwrap();
    let grip: Port<f32, bool, usage::Receive, AnyUser, 2> =
        Port::new(PortSpec::new("GRIP", "GRIPPER").user_list(["ROBOT"]));
    let _exported = export(&gripper_host, &grip).await.unwrap();
    let mut gripper = grip.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((width, reply)) = gripper.receive().await {
            reply.reply(width < 0.05);
        }
    });
    let robot: Imported<f32, bool, usage::Receive> =
        import(&robot_host, "GRIP", "GRIPPER", "ROBOT")
            .await
            .unwrap();
    let mut robot = robot.port().user_named("ROBOT").unwrap();
    for _ in 0..20 {
        let closed = within(PROMPTLY, "a round trip over TLS", robot.send(0.01)).await;
        assert!(closed.unwrap(), "an answer that was not the gripper's");
    }

    // Neither the intruder, claiming ROBOT's name from a link straight to the gripper's host,
    // nor a host with no certificate at all, reaches the gripper's GRIP.
    let intruder_host = Host::builder("tls_cell")
        .tls(authority.host("intruder-host"))
        .connect(&gripper_endpoint)
        .open()
        .await
        .unwrap();
    let plain_host = Host::builder("tls_cell")
        .connect(&gripper_endpoint)
        .open()
        .await
        .unwrap();
    let (intruding, plain) = tokio::join!(
        import::<Imported<f32, bool, usage::Receive>>(&intruder_host, "GRIP", "GRIPPER", "ROBOT"),
        import::<Imported<f32, bool, usage::Receive>>(&plain_host, "GRIP", "GRIPPER", "ROBOT"),
    );
    for refused in [intruding.unwrap_err(), plain.unwrap_err()] {
        let no_owner = ZenohError::NoOwner {
            port: "GRIP".into(),
        };
        assert_eq!(refused, no_owner);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn admitting_ports_without_tls_is_refused_by_name() {
    let refused = Host::builder("tls_cell")
        .admit("GRIP", "gripper-host", GRIP_USERS)
        .open()
        .await
        .err()
        .unwrap();
    assert_eq!(
        refused.to_string(),
        "zenoh session: port GRIP admits hosts by their certificates, and this host has no TLS"
    );
}

/// A port whose owner starts each rendezvous crosses under admission too: the owner's
/// broadcasts reach the admitted user's host on its module's `deliver` key.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_admitted_broadcast_reaches_its_listener() {
    let authority = Authority::new("broadcast");
    let endpoint = tls_endpoint();
    let open = |name: &str, listens: bool| {
        let builder = Host::builder("tls_alarm_cell")
            .tls(authority.host(name))
            .admit("ALARM", "line-host", [("PANEL", "panel-host")]);
        let builder = if listens {
            builder.listen(&endpoint)
        } else {
            builder.connect(&endpoint)
        };
        builder.open()
    };
    let line_host = open("line-host", true).await.unwrap();
    let alarm: Port<u32, u32, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("ALARM", "LINE").user_list(["PANEL"]));
    let _exported = export(&line_host, &alarm).await.unwrap();
    let panel_host = open("panel-host", false).await.unwrap();
    let imported: Imported<u32, u32, usage::SendAll> =
        import(&panel_host, "ALARM", "LINE", "PANEL").await.unwrap();
    let mut panel = imported.port().user_named("PANEL").unwrap();
    tokio::spawn(async move {
        while let Ok((n, reply)) = panel.receive().await {
            let _ = reply.reply(n + 1);
        }
    });
    let mut line = alarm.owner().unwrap();
    let answered = within(PROMPTLY, "an admitted broadcast", async {
        while alarm.users_attached() < 1 {
            tokio::task::yield_now().await;
        }
        line.send_all(41).await.map(|broadcast| broadcast.first)
    })
    .await;
    assert_eq!(answered.unwrap(), 42);
}

/// A port misspelt, or forgotten, in a host's admissions would only ever time out: it is
/// refused at once, by name, when the host exports or imports it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_port_the_host_does_not_admit_is_refused_at_once_by_name() {
    let authority = Authority::new("unadmitted");
    let host = host(authority.host("gripper-host"), &tls_endpoint(), true).await;
    let misspelt: Port<f32, bool, usage::Receive> = Port::new(PortSpec::new("GIRP", "GRIPPER"));
    let not_admitted = ZenohError::NotAdmitted {
        port: "GIRP".into(),
    };
    assert_eq!(export(&host, &misspelt).await.unwrap_err(), not_admitted);
    let imported =
        import::<Imported<f32, bool, usage::Receive>>(&host, "GIRP", "GRIPPER", "ROBOT").await;
    assert_eq!(imported.unwrap_err(), not_admitted);
    assert!(not_admitted.to_string().contains("HostBuilder::admit"));
}

/// Module names are bound to hosts: a host admitted for one of a port's modules, that claims
/// another module's name on the port, is refused by the owner's host, though it is served
/// under its own module's name.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_admitted_host_cannot_claim_another_hosts_module() {
    let authority = Authority::new("bound");
    let endpoint = tls_endpoint();
    let gripper_host = host(authority.host("gripper-host"), &endpoint, true).await;
    let grip: Port<f32, bool, usage::Receive, AnyUser, 2> =
        Port::new(PortSpec::new("GRIP", "GRIPPER").user_list(["ROBOT", "PANEL"]));
    let _exported = export(&gripper_host, &grip).await.unwrap();
    let mut gripper = grip.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((width, reply)) = gripper.receive().await {
            reply.reply(width < 0.05);
        }
    });
    // The panel's host, admitted for PANEL, its own admissions left out so that nothing on
    // its side stops it: served as PANEL, refused as ROBOT, whose host is robot-host.
    let panel_host = Host::builder("tls_cell")
        .tls(authority.host("panel-host"))
        .connect(&endpoint)
        .open()
        .await
        .unwrap();
    let panel: Imported<f32, bool, usage::Receive> =
        import(&panel_host, "GRIP", "GRIPPER", "PANEL")
            .await
            .unwrap();
    let mut panel = panel.port().user_named("PANEL").unwrap();
    let closed = within(PROMPTLY, "the panel's own request", panel.send(0.01)).await;
    assert!(closed.unwrap());
    let claimed =
        import::<Imported<f32, bool, usage::Receive>>(&panel_host, "GRIP", "GRIPPER", "ROBOT")
            .await
            .unwrap_err();
    assert_eq!(
        claimed,
        ZenohError::NoOwner {
            port: "GRIP".into()
        }
    );
    assert_eq!(grip.users_attached(), 1, "ROBOT's place was taken");

    // A host that admits GRIP refuses at once, by name, a module it does not admit.
    let robot_host = host(authority.host("robot-host"), &endpoint, false).await;
    let stranger =
        import::<Imported<f32, bool, usage::Receive>>(&robot_host, "GRIP", "GRIPPER", "STRANGER")
            .await
            .unwrap_err();
    assert_eq!(
        stranger,
        ZenohError::ModuleNotAdmitted {
            port: "GRIP".into(),
            module: "STRANGER".into()
        }
    );
    assert!(
        stranger.to_string().contains("module STRANGER"),
        "{stranger}"
    );
}
