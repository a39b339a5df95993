//! How `rmw_zenoh` names things (its design document, "Topic and Service name mapping" and
//! "Graph Cache"): the key expression a topic's or a service's data goes on, and the
//! liveliness token by which a node and each of its endpoints appear in the ROS 2 graph.

use crate::{Ros2Error, TypeHash};

/// What a liveliness token says its entity is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntityKind {
    /// A node (`NN`).
    Node,
    /// A topic's publisher (`MP`).
    Publisher,
    /// A topic's subscription (`MS`).
    Subscription,
    /// A service's server (`SS`).
    ServiceServer,
    /// A service's client (`SC`).
    ServiceClient,
}

impl EntityKind {
    fn code(self) -> &'static str {
        match self {
            EntityKind::Node => "NN",
            EntityKind::Publisher => "MP",
            EntityKind::Subscription => "MS",
            EntityKind::ServiceServer => "SS",
            EntityKind::ServiceClient => "SC",
        }
    }
}

/// The admin space every liveliness token of the ROS 2 graph lies in.
const GRAPH: &str = "@ros2_lv";

/// `name` as one chunk of a token: every `/` as `%` (the root, `/`, is `%`).
fn mangle(name: &str) -> String {
    name.replace('/', "%")
}

/// A node: where it is in the graph, and the token parts its endpoints share.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeName {
    /// The ROS domain (`ROS_DOMAIN_ID`).
    pub domain: u32,
    /// Its namespace: `/`, or `/a/b`.
    pub namespace: String,
    /// Its name.
    pub name: String,
}

impl NodeName {
    /// Node `name` in `namespace` of `domain`; refused, naming what is wrong, unless the
    /// name is `[A-Za-z_][A-Za-z0-9_]*` and the namespace `/` or `/` then such names
    /// joined by `/`.
    pub fn new(domain: u32, namespace: &str, name: &str) -> Result<Self, Ros2Error> {
        if !is_token(name) {
            return Err(Ros2Error::name("node name", name));
        }
        let valid_namespace = namespace == "/"
            || namespace
                .strip_prefix('/')
                .is_some_and(|rest| rest.split('/').all(is_token));
        if !valid_namespace {
            return Err(Ros2Error::name("namespace", namespace));
        }
        Ok(Self {
            domain,
            namespace: namespace.to_owned(),
            name: name.to_owned(),
        })
    }

    /// The fully qualified name of topic or service `name` of this node: itself if it
    /// starts with `/`, else in the node's namespace. Refused unless each part is
    /// `[A-Za-z_][A-Za-z0-9_]*`.
    pub fn qualified(&self, name: &str) -> Result<String, Ros2Error> {
        let qualified = if name.starts_with('/') {
            name.to_owned()
        } else if self.namespace == "/" {
            format!("/{name}")
        } else {
            format!("{}/{name}", self.namespace)
        };
        let valid = qualified
            .strip_prefix('/')
            .is_some_and(|rest| rest.split('/').all(is_token));
        if valid {
            Ok(qualified)
        } else {
            Err(Ros2Error::name("topic or service name", name))
        }
    }

    /// The liveliness token of this node, of session `zid`, as node `node_id`.
    pub fn node_token(&self, zid: &str, node_id: u64) -> String {
        format!(
            "{GRAPH}/{}/{zid}/{node_id}/{node_id}/{}/%/{}/{}",
            self.domain,
            EntityKind::Node.code(),
            mangle(&self.namespace),
            self.name
        )
    }

    /// The liveliness token of an endpoint of this node: `kind`, entity `entity_id`, on
    /// `topic` (fully qualified) of type `dds_type` with `hash`, at `qos`.
    #[allow(clippy::too_many_arguments)]
    pub fn entity_token(
        &self,
        zid: &str,
        node_id: u64,
        entity_id: u64,
        kind: EntityKind,
        topic: &str,
        dds_type: &str,
        hash: &TypeHash,
        qos: &Qos,
    ) -> String {
        format!(
            "{GRAPH}/{}/{zid}/{node_id}/{entity_id}/{}/%/{}/{}/{}/{dds_type}/{hash}/{}",
            self.domain,
            kind.code(),
            mangle(&self.namespace),
            self.name,
            mangle(topic),
            qos.key()
        )
    }

    /// The key expression the data of topic or service `topic` (fully qualified) of type
    /// `dds_type` with `hash` goes on: `<domain>/<topic without its outer slashes>/<type>/
    /// <hash>`.
    pub fn data_key(&self, topic: &str, dds_type: &str, hash: &TypeHash) -> String {
        let topic = topic.trim_matches('/');
        format!("{}/{topic}/{dds_type}/{hash}", self.domain)
    }
}

/// `[A-Za-z_][A-Za-z0-9_]*`: a ROS 2 name's part.
fn is_token(part: &str) -> bool {
    let mut chars = part.chars();
    chars
        .next()
        .is_some_and(|first| first.is_ascii_alphabetic() || first == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The quality of service of an endpoint: reliable or best effort, volatile, the last
/// `depth` messages kept. (Durability other than volatile, deadlines, lifespans and
/// liveliness other than automatic are not offered.)
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Reliable (`true`) or best effort.
    pub reliable: bool,
    /// How many messages are kept.
    pub depth: u32,
}

impl Qos {
    /// Reliable, the last ten kept: ROS 2's default for topics and services.
    pub const DEFAULT: Qos = Qos {
        reliable: true,
        depth: 10,
    };

    /// As a token's last chunk: each field empty where it is `rmw_zenoh`'s default
    /// (reliable, volatile, keep-last, depth 42, durations infinite, liveliness automatic).
    pub fn key(&self) -> String {
        let reliability = if self.reliable { "" } else { "2" };
        let depth = if self.depth == 42 {
            String::new()
        } else {
            self.depth.to_string()
        };
        format!("{reliability}::,{depth}:,:,:,,")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RosMessage;
    use crate::msgs::std_msgs;

    /// The examples of `rmw_zenoh`'s design document.
    #[test]
    fn keys_and_tokens_are_rmw_zenohs() {
        let talker = NodeName::new(0, "/", "talker").unwrap();
        let hash = std_msgs::String::type_hash();
        let chatter = talker.qualified("chatter").unwrap();
        assert_eq!(
            talker.data_key(&chatter, &std_msgs::String::dds_type_name(), &hash),
            "0/chatter/std_msgs::msg::dds_::String_/\
             RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
        );
        let zid = "8b20917502ee955ac4476e0266340d5c";
        assert_eq!(
            talker.node_token(zid, 0),
            "@ros2_lv/0/8b20917502ee955ac4476e0266340d5c/0/0/NN/%/%/talker"
        );
        assert_eq!(
            talker.entity_token(
                zid,
                0,
                10,
                EntityKind::Publisher,
                &chatter,
                &std_msgs::String::dds_type_name(),
                &hash,
                &Qos {
                    reliable: true,
                    depth: 7
                }
            ),
            "@ros2_lv/0/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/\
             std_msgs::msg::dds_::String_/\
             RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18/::,7:,:,:,,"
        );
        let listener = NodeName::new(0, "/robot1", "listener").unwrap();
        let topic = listener.qualified("chatter").unwrap();
        assert_eq!(topic, "/robot1/chatter");
        assert!(
            listener
                .entity_token(
                    zid,
                    3,
                    4,
                    EntityKind::Subscription,
                    &topic,
                    "t",
                    &hash,
                    &Qos::DEFAULT
                )
                .ends_with("/MS/%/%robot1/listener/%robot1%chatter/t/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18/::,10:,:,:,,")
        );
        assert_eq!(
            Qos {
                reliable: false,
                depth: 42
            }
            .key(),
            "2::,:,:,:,,"
        );
    }

    #[test]
    fn a_name_ros_2_would_refuse_is_refused_by_name() {
        for (namespace, name, wrong, value) in [
            ("/", "1talker", "node name", "1talker"),
            ("/", "talk-er", "node name", "talk-er"),
            ("robot", "talker", "namespace", "robot"),
            ("/robot/", "talker", "namespace", "/robot/"),
        ] {
            let refused = NodeName::new(0, namespace, name);
            assert!(
                matches!(&refused, Err(Ros2Error::Name { what, name, .. }) if *what == wrong && name == value),
                "{namespace:?} {name:?}: {refused:?}"
            );
        }
        let node = NodeName::new(0, "/cell", "chip_cell").unwrap();
        assert_eq!(node.qualified("/alarms").unwrap(), "/alarms");
        assert!(node.qualified("joint states").is_err());
        assert!(node.qualified("").is_err());
    }
}
