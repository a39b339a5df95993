//! Who may connect: mutual TLS between a cell's hosts, and zenoh's access control on each
//! port's keys, by the common names of the hosts' certificates.

use std::path::PathBuf;

use crate::ZenohError;
use crate::key::checked;

/// A host's certificate and key, and the authority that signed the certificate of every host
/// of the cell: PEM files. With them, hosts connect over TLS (`tls/<address>:<port>`
/// endpoints) and each proves who it is to the other; a host without a certificate signed
/// by the authority is not let in.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TlsFiles {
    /// The certificate authority of the cell.
    pub authority: PathBuf,
    /// This host's certificate, signed by the authority; its common name names the host.
    pub certificate: PathBuf,
    /// This host's private key.
    pub key: PathBuf,
}

/// The hosts admitted to one port's keys on this host, by certificate common name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Admitted {
    pub(crate) port: String,
    /// The host of the port's owner: it alone may serve the port.
    pub(crate) owner: String,
    /// The hosts of the modules on the port's user list: they may ask it.
    pub(crate) users: Vec<String>,
}

/// The session settings for mutual TLS with `files`.
pub(crate) fn tls_settings(files: &TlsFiles) -> Vec<(&'static str, String)> {
    let path = |p: &PathBuf| serde_json::Value::from(p.display().to_string()).to_string();
    vec![
        (
            "transport/link/tls/root_ca_certificate",
            path(&files.authority),
        ),
        (
            "transport/link/tls/listen_certificate",
            path(&files.certificate),
        ),
        ("transport/link/tls/listen_private_key", path(&files.key)),
        (
            "transport/link/tls/connect_certificate",
            path(&files.certificate),
        ),
        ("transport/link/tls/connect_private_key", path(&files.key)),
        ("transport/link/tls/enable_mtls", "true".to_owned()),
        // Hosts are named by their certificates' common names, not by their addresses.
        (
            "transport/link/tls/verify_name_on_connect",
            "false".to_owned(),
        ),
    ]
}

/// zenoh's access control for `cell`, in JSON5: nothing is allowed but what `admitted`
/// allows. On each port's keys, its owner's host may do anything; its users' hosts may ask
/// it (queries), watch its owner's token, hold tokens of their own modules and serve their
/// modules' `deliver` keys, and are sent its replies, its owner's token and its broadcasts;
/// any other host is let do nothing.
pub(crate) fn access_control(cell: &str, admitted: &[Admitted]) -> Result<String, ZenohError> {
    let (mut rules, mut subjects, mut policies) = (Vec::new(), Vec::new(), Vec::new());
    for (i, port) in admitted.iter().enumerate() {
        checked("port", &port.port)?;
        let key = |kind: &str| format!("\"imrs/{cell}/{kind}/{}\"", port.port);
        let asked = [key("port"), key("connect"), key("live")].join(", ");
        let tokens = format!("\"imrs/{cell}/user/{}/**\"", port.port);
        let deliver = format!("\"imrs/{cell}/deliver/{}/**\"", port.port);
        let names = |hosts: &[String]| {
            hosts
                .iter()
                .map(|h| serde_json::Value::from(h.as_str()).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        rules.push(format!(
            "{{ id: \"owner{i}\", flows: [\"egress\", \"ingress\"], permission: \"allow\", \
             messages: [\"put\", \"delete\", \"declare_subscriber\", \"query\", \"reply\", \
             \"declare_queryable\", \"liveliness_token\", \"liveliness_query\", \
             \"declare_liveliness_subscriber\"], key_exprs: [{asked}, {tokens}, {deliver}] }}"
        ));
        rules.push(format!(
            "{{ id: \"ask{i}\", flows: [\"ingress\"], permission: \"allow\", \
             messages: [\"query\", \"liveliness_query\", \"declare_liveliness_subscriber\"], \
             key_exprs: [{asked}] }}"
        ));
        rules.push(format!(
            "{{ id: \"hold{i}\", flows: [\"ingress\"], permission: \"allow\", \
             messages: [\"liveliness_token\"], key_exprs: [{tokens}] }}"
        ));
        rules.push(format!(
            "{{ id: \"told{i}\", flows: [\"egress\"], permission: \"allow\", \
             messages: [\"reply\", \"declare_queryable\", \"liveliness_token\", \"declare_liveliness_subscriber\"], \
             key_exprs: [{asked}, {tokens}] }}"
        ));
        // For a port whose owner starts each rendezvous: each user's host serves its
        // modules' `deliver` keys, which the owner's host asks.
        rules.push(format!(
            "{{ id: \"serve{i}\", flows: [\"ingress\"], permission: \"allow\", \
             messages: [\"declare_queryable\", \"reply\"], key_exprs: [{deliver}] }}"
        ));
        rules.push(format!(
            "{{ id: \"reach{i}\", flows: [\"egress\"], permission: \"allow\", \
             messages: [\"query\", \"liveliness_query\"], key_exprs: [{deliver}, {tokens}] }}"
        ));
        subjects.push(format!(
            "{{ id: \"owner{i}\", cert_common_names: [{}] }}",
            names(std::slice::from_ref(&port.owner))
        ));
        policies.push(format!(
            "{{ rules: [\"owner{i}\"], subjects: [\"owner{i}\"] }}"
        ));
        if !port.users.is_empty() {
            subjects.push(format!(
                "{{ id: \"users{i}\", cert_common_names: [{}] }}",
                names(&port.users)
            ));
            policies.push(format!(
                "{{ rules: [\"ask{i}\", \"hold{i}\", \"told{i}\", \"serve{i}\", \"reach{i}\"], \
                 subjects: [\"users{i}\"] }}"
            ));
        }
    }
    Ok(format!(
        "{{ enabled: true, default_permission: \"deny\", rules: [{}], subjects: [{}], \
         policies: [{}] }}",
        rules.join(", "),
        subjects.join(", "),
        policies.join(", ")
    ))
}
