//! The key expressions a cell's ports use on zenoh, and the names allowed in them.
//!
//! - `imrs/<cell>/port/<PORT>/<MODULE>`: a module's request (a send, a query) to the port's
//!   owner. The module is named by the key, so that access control can bind a module's
//!   name to its host.
//! - `imrs/<cell>/connect/<PORT>/<MODULE>`: a module's connection, checked against the
//!   port's restrictions before any request.
//! - `imrs/<cell>/live/<PORT>`: a liveliness token, held by the owner's host while it
//!   exports the port.
//! - `imrs/<cell>/user/<PORT>/<MODULE>`: a liveliness token, held by a user's host while
//!   it imports the port for the module.
//! - `imrs/<cell>/deliver/<PORT>/<MODULE>`: for a port whose owner starts each rendezvous
//!   (`SENDALL`, `CALLALL`, `QUERY`), the user's host's queryable, where the owner's
//!   broadcasts and queries reach the module.

use crate::ZenohError;

/// Refuses a name that would change the meaning of a key expression it is part of.
pub(crate) fn checked<'a>(what: &'static str, name: &'a str) -> Result<&'a str, ZenohError> {
    let bad = name.is_empty()
        || name.starts_with('@')
        || name.chars().any(|c| {
            matches!(c, '/' | '*' | '$' | '?' | '#' | '"' | '\\')
                || c.is_control()
                || c.is_whitespace()
        });
    if bad {
        Err(ZenohError::BadName {
            what,
            name: name.to_owned(),
        })
    } else {
        Ok(name)
    }
}

/// The keys of one port of one cell.
#[derive(Debug, Clone)]
pub(crate) struct Keys {
    request: String,
    connect: String,
    pub(crate) live: String,
    user: String,
    deliver: String,
}

impl Keys {
    pub(crate) fn new(cell: &str, port: &str) -> Result<Self, ZenohError> {
        let port = checked("port", port)?;
        Ok(Self {
            request: format!("imrs/{cell}/port/{port}"),
            connect: format!("imrs/{cell}/connect/{port}"),
            live: format!("imrs/{cell}/live/{port}"),
            user: format!("imrs/{cell}/user/{port}"),
            deliver: format!("imrs/{cell}/deliver/{port}"),
        })
    }

    /// Where `module`'s requests go.
    pub(crate) fn request(&self, module: &str) -> String {
        format!("{}/{module}", self.request)
    }

    /// Where `module` connects.
    pub(crate) fn connect(&self, module: &str) -> String {
        format!("{}/{module}", self.connect)
    }

    /// Where the owner's host takes every module's requests.
    pub(crate) fn requests(&self) -> String {
        format!("{}/*", self.request)
    }

    /// Where the owner's host takes every module's connections.
    pub(crate) fn connects(&self) -> String {
        format!("{}/*", self.connect)
    }

    /// The key under which the importing hosts' tokens for the port's users lie.
    pub(crate) fn user_prefix(&self) -> &str {
        &self.user
    }

    /// Where the owner's broadcasts and queries reach `module`'s host: a queryable of that
    /// host's, for a port whose owner starts each rendezvous.
    pub(crate) fn deliver(&self, module: &str) -> String {
        format!("{}/{module}", self.deliver)
    }

    /// The token of `module`'s host while it uses the port.
    pub(crate) fn user(&self, module: &str) -> String {
        format!("{}/{module}", self.user)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_that_would_widen_a_key_expression_is_refused_by_name() {
        for name in [
            "",
            "A/B",
            "*",
            "A**",
            "$x",
            "Q?",
            "#",
            "@live",
            "TWO WORDS",
            "A\"B",
            "A\\B",
        ] {
            let error = checked("module", name).unwrap_err();
            assert!(error.to_string().contains(&format!("{name:?}")), "{error}");
        }
        assert_eq!(checked("module", "ROBOT_1").unwrap(), "ROBOT_1");
        let keys = Keys::new("cell", "DOUBLE").unwrap();
        assert_eq!(keys.request("ROBOT_1"), "imrs/cell/port/DOUBLE/ROBOT_1");
        assert_eq!(keys.requests(), "imrs/cell/port/DOUBLE/*");
    }
}
