//! A host of a cell: one zenoh session, with its endpoints and its lease.

use std::time::Duration;

use crate::ZenohError;
use crate::access::{Admitted, TlsFiles, access_control, tls_settings};
use crate::key::checked;

/// One host's view of a cell on zenoh: a zenoh session in peer mode, which finds other
/// hosts through the endpoints it is given (no router, no multicast scouting), and the
/// cell's name, which every key expression of its ports starts with.
///
/// Cheap to clone: clones share the session.
#[derive(Clone)]
pub struct Host {
    pub(crate) session: zenoh::Session,
    pub(crate) cell: String,
    pub(crate) lease: Duration,
    /// The ports admitted and their users' modules, if this host admits ports: no other
    /// port can cross, and no other module use one.
    admitted: Option<Vec<(String, Vec<String>)>>,
}

/// How to open a [`Host`]: its endpoints and lease.
#[derive(Debug, Clone)]
pub struct HostBuilder {
    cell: String,
    listen: Vec<String>,
    connect: Vec<String>,
    lease: Duration,
    tls: Option<TlsFiles>,
    admitted: Vec<Admitted>,
}

impl Host {
    /// The lease a host's links have unless told otherwise: a peer killed or cut off is
    /// seen gone within it.
    pub const DEFAULT_LEASE: Duration = Duration::from_secs(2);

    /// A host of cell `cell`, to be opened with [`HostBuilder::open`].
    pub fn builder(cell: &str) -> HostBuilder {
        HostBuilder {
            cell: cell.to_owned(),
            listen: Vec::new(),
            connect: Vec::new(),
            lease: Self::DEFAULT_LEASE,
            tls: None,
            admitted: Vec::new(),
        }
    }

    /// The cell's name.
    pub fn cell(&self) -> &str {
        &self.cell
    }

    /// The lease of this host's links.
    pub fn lease(&self) -> Duration {
        self.lease
    }

    /// The zenoh session, for what this crate does not wrap.
    pub fn session(&self) -> &zenoh::Session {
        &self.session
    }

    /// Refuses, naming it, a port this host cannot carry: one it does not admit, when it
    /// admits ports. Without the check such a port would only ever time out.
    pub(crate) fn carries(&self, port: &str) -> Result<(), ZenohError> {
        self.admitted_users(port).map(drop)
    }

    /// Refuses, naming them, a port this host cannot carry, or a module it does not admit to
    /// the port as one of its users, when it admits ports.
    pub(crate) fn carries_for(&self, port: &str, module: &str) -> Result<(), ZenohError> {
        match self.admitted_users(port)? {
            Some(users) if !users.iter().any(|user| user == module) => {
                Err(ZenohError::ModuleNotAdmitted {
                    port: port.to_owned(),
                    module: module.to_owned(),
                })
            }
            _ => Ok(()),
        }
    }

    /// The modules admitted to use `port`, if this host admits ports; refused if it admits
    /// ports but not this one.
    fn admitted_users(&self, port: &str) -> Result<Option<&[String]>, ZenohError> {
        let Some(ports) = &self.admitted else {
            return Ok(None);
        };
        match ports.iter().find(|(admitted, _)| admitted == port) {
            Some((_, users)) => Ok(Some(users)),
            None => Err(ZenohError::NotAdmitted {
                port: port.to_owned(),
            }),
        }
    }

    /// Whether a host of the cell is seen exporting `port` now, by its liveliness token.
    pub async fn is_exported(&self, port: &str) -> Result<bool, ZenohError> {
        let keys = crate::key::Keys::new(&self.cell, port)?;
        Ok(crate::watch::alive(&self.session, &keys.live).await)
    }

    /// Closes the session: every port it exports is withdrawn, and its peers see it gone.
    pub async fn close(&self) -> Result<(), ZenohError> {
        self.session.close().await.map_err(ZenohError::session)
    }
}

impl HostBuilder {
    /// Listens on `endpoint` (`tcp/10.0.0.1:7447`) for other hosts.
    pub fn listen(mut self, endpoint: impl Into<String>) -> Self {
        self.listen.push(endpoint.into());
        self
    }

    /// Connects to `endpoint`, another host's (or a zenoh router's), and keeps trying while
    /// it is unreachable.
    pub fn connect(mut self, endpoint: impl Into<String>) -> Self {
        self.connect.push(endpoint.into());
        self
    }

    /// The lease of this host's links: how long a silent peer is kept before it is seen
    /// gone. Four keep-alives are sent in each lease.
    pub fn lease(mut self, lease: Duration) -> Self {
        self.lease = lease;
        self
    }

    /// Mutual TLS with the cell's other hosts: each proves who it is with a certificate
    /// signed by the cell's authority. Give `tls/<address>:<port>` endpoints.
    pub fn tls(mut self, files: TlsFiles) -> Self {
        self.tls = Some(files);
        self
    }

    /// Admits to port `port`'s keys on this host only `owner_host`, the host of its owner,
    /// which alone may serve it, and the `(module, host)` pairs of `users`: each module on
    /// the port's user list with the host it runs on, which may ask the port for that module
    /// and no other. Hosts are named by their certificates' common names. Once any port is
    /// admitted, this host lets no other host do anything else: every port that crosses to
    /// or from it must be admitted, on the owner's host and on each user's, and a module not
    /// admitted to a port cannot import it. Needs [`tls`](Self::tls).
    ///
    /// ```
    /// # let files = imrs_zenoh::TlsFiles { authority: "a".into(), certificate: "c".into(), key: "k".into() };
    /// let builder = imrs_zenoh::Host::builder("my_cell")
    ///     .tls(files)
    ///     .admit("GRIP", "gripper-host", [("ROBOT_1", "robot-host"), ("ROBOT_2", "robot-host")]);
    /// ```
    pub fn admit<M: Into<String>, H: Into<String>>(
        mut self,
        port: &str,
        owner_host: &str,
        users: impl IntoIterator<Item = (M, H)>,
    ) -> Self {
        self.admitted.push(Admitted {
            port: port.to_owned(),
            owner: owner_host.to_owned(),
            users: users
                .into_iter()
                .map(|(module, host)| (module.into(), host.into()))
                .collect(),
        });
        self
    }

    /// Opens the session. Refused, naming it, if the cell's name cannot be part of a key
    /// expression, ports are admitted without TLS, or zenoh refuses an endpoint or a file.
    pub async fn open(self) -> Result<Host, ZenohError> {
        checked("cell", &self.cell)?;
        if let (None, Some(first)) = (&self.tls, self.admitted.first()) {
            return Err(ZenohError::Session {
                reason: format!(
                    "port {} admits hosts by their certificates, and this host has no TLS",
                    first.port
                ),
            });
        }
        let mut config = zenoh::Config::default();
        let settings = [
            ("mode", "\"peer\"".to_owned()),
            ("scouting/multicast/enabled", "false".to_owned()),
            ("listen/endpoints", json_list(&self.listen)),
            ("connect/endpoints", json_list(&self.connect)),
            (
                "transport/link/tx/lease",
                self.lease.as_millis().max(1).to_string(),
            ),
            // A host tries again an endpoint it lost within half a second, so that a host
            // that comes back is found about as soon as it listens.
            (
                "connect/retry",
                "{ period_init_ms: 100, period_max_ms: 500, period_increase_factor: 2 }".to_owned(),
            ),
        ];
        let mut settings = settings.to_vec();
        if let Some(files) = &self.tls {
            settings.extend(tls_settings(files));
        }
        if !self.admitted.is_empty() {
            settings.push((
                "access_control",
                access_control(&self.cell, &self.admitted)?,
            ));
        }
        for (key, value) in settings {
            config
                .insert_json5(key, &value)
                .map_err(|error| ZenohError::session(format!("{key} = {value}: {error}")))?;
        }
        let session = zenoh::open(config).await.map_err(ZenohError::session)?;
        let admitted = (!self.admitted.is_empty()).then(|| {
            self.admitted
                .iter()
                .map(|a| {
                    let users = a.users.iter().map(|(module, _)| module.clone()).collect();
                    (a.port.clone(), users)
                })
                .collect()
        });
        Ok(Host {
            session,
            cell: self.cell,
            lease: self.lease,
            admitted,
        })
    }
}

/// `["a", "b"]`: the endpoints as a JSON list of strings.
fn json_list(items: &[String]) -> String {
    serde_json::Value::from(items.to_vec()).to_string()
}
