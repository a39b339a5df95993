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
    /// The modules on the port's user list, each with its host: a host may ask the port
    /// for its own modules only.
    pub(crate) users: Vec<(String, String)>,
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
/// allows. On each port's keys, its owner's host may do anything; each user's host may ask
/// it for its own modules (connections and requests on keys that end with the module's
/// name), watch its owner's token, hold its own modules' tokens and serve their `deliver`
/// keys, and is sent the port's replies, its owner's token and its broadcasts; any other
/// host is let do nothing.
pub(crate) fn access_control(cell: &str, admitted: &[Admitted]) -> Result<String, ZenohError> {
    let quoted = |text: &str| serde_json::Value::from(text).to_string();
    let list = |keys: &[String]| {
        keys.iter()
            .map(|k| quoted(k))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (mut rules, mut subjects, mut policies) = (Vec::new(), Vec::new(), Vec::new());
    let mut rule = |id: &str, flow: &str, messages: &[&str], keys: &[String]| {
        let messages = messages.iter().map(|m| quoted(m)).collect::<Vec<_>>();
        rules.push(format!(
            "{{ id: {}, flows: [{flow}], permission: \"allow\", messages: [{}], \
             key_exprs: [{}] }}",
            quoted(id),
            messages.join(", "),
            list(keys)
        ));
    };
    const BOTH: &str = "\"egress\", \"ingress\"";
    const IN: &str = "\"ingress\"";
    const OUT: &str = "\"egress\"";
    for (i, port) in admitted.iter().enumerate() {
        let p = checked("port", &port.port)?;
        let key = |kind: &str, rest: &str| format!("imrs/{cell}/{kind}/{p}{rest}");
        let live = key("live", "");
        let (requests, connects) = (key("port", "/*"), key("connect", "/*"));
        let (tokens, deliver) = (key("user", "/**"), key("deliver", "/**"));
        rule(
            &format!("owner{i}"),
            BOTH,
            &[
                "put",
                "delete",
                "declare_subscriber",
                "query",
                "reply",
                "declare_queryable",
                "liveliness_token",
                "liveliness_query",
                "declare_liveliness_subscriber",
            ],
            &[
                requests.clone(),
                connects.clone(),
                live.clone(),
                tokens.clone(),
                deliver.clone(),
            ],
        );
        subjects.push(format!(
            "{{ id: \"owner{i}\", cert_common_names: [{}] }}",
            quoted(&port.owner)
        ));
        policies.push(format!(
            "{{ rules: [\"owner{i}\"], subjects: [\"owner{i}\"] }}"
        ));
        if port.users.is_empty() {
            continue;
        }
        // To every user's host: the owner's replies, declarations and token, its
        // broadcasts and queries on the `deliver` keys, and its looks at the users' tokens.
        rule(
            &format!("told{i}"),
            OUT,
            &[
                "reply",
                "declare_queryable",
                "liveliness_token",
                "declare_liveliness_subscriber",
            ],
            &[requests, connects, live.clone(), tokens.clone()],
        );
        rule(
            &format!("reach{i}"),
            OUT,
            &["query", "liveliness_query"],
            &[deliver, tokens],
        );
        // From each user's host: what its own modules do, on keys named for them.
        let mut hosts: std::collections::BTreeMap<&str, Vec<&str>> = Default::default();
        for (module, host) in &port.users {
            hosts
                .entry(host)
                .or_default()
                .push(checked("module", module)?);
        }
        for (j, (host, modules)) in hosts.into_iter().enumerate() {
            let each = |kind: &str| -> Vec<String> {
                modules
                    .iter()
                    .map(|m| key(kind, &format!("/{m}")))
                    .collect()
            };
            let mut asked = each("port");
            asked.extend(each("connect"));
            asked.push(live.clone());
            rule(
                &format!("ask{i}_{j}"),
                IN,
                &["query", "liveliness_query", "declare_liveliness_subscriber"],
                &asked,
            );
            rule(
                &format!("hold{i}_{j}"),
                IN,
                &["liveliness_token"],
                &each("user"),
            );
            rule(
                &format!("serve{i}_{j}"),
                IN,
                &["declare_queryable", "reply"],
                &each("deliver"),
            );
            subjects.push(format!(
                "{{ id: \"user{i}_{j}\", cert_common_names: [{}] }}",
                quoted(host)
            ));
            policies.push(format!(
                "{{ rules: [\"told{i}\", \"reach{i}\", \"ask{i}_{j}\", \"hold{i}_{j}\", \
                 \"serve{i}_{j}\"], subjects: [\"user{i}_{j}\"] }}"
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
