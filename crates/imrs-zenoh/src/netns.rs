//! Hosts of a cell on one machine: network namespaces, each joined to this one by a veth
//! link, as tests and demonstrations make them (`ip netns`, from iproute2; root is needed).
//! Where they cannot be made, [`Netns::make`] says why, and the caller falls back to
//! loopback and says so.

use std::process::Command;

/// A network namespace and the veth link that joins it to this one, removed when dropped.
#[derive(Debug)]
pub struct Netns {
    name: String,
    outside: String,
    inside_address: String,
    outside_address: String,
}

impl Netns {
    /// Makes namespace `k` of this process, or says why it cannot (not root, no `ip`).
    /// Each `k` has a link and a /30 subnet of its own.
    pub fn make(k: u8) -> Result<Self, String> {
        let id = std::process::id() % 100_000;
        let (name, outside, inside) = (
            format!("imrs-{id}-{k}"),
            format!("imrso{id}x{k}"),
            format!("imrsi{id}x{k}"),
        );
        let subnet = format!("10.{}.{}", 100 + k % 100, id % 250);
        let netns = Self {
            name: name.clone(),
            outside: outside.clone(),
            inside_address: format!("{subnet}.2"),
            outside_address: format!("{subnet}.1"),
        };
        let link = [
            "link", "add", &outside, "type", "veth", "peer", "name", &inside, "netns", &name,
        ];
        let steps: [Vec<String>; 7] = [
            args(&["netns", "add", &name]),
            args(&link),
            args(&["addr", "add", &format!("{subnet}.1/30"), "dev", &outside]),
            args(&["link", "set", &outside, "up"]),
            netns.inside(&["addr", "add", &format!("{subnet}.2/30"), "dev", &inside]),
            netns.inside(&["link", "set", &inside, "up"]),
            netns.inside(&["link", "set", "lo", "up"]),
        ];
        for step in steps {
            ip(&step)?;
        }
        Ok(netns)
    }

    /// Its name, for `ip netns exec`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its address on the link.
    pub fn inside_address(&self) -> &str {
        &self.inside_address
    }

    /// This namespace's address on the link, where the namespace reaches this one.
    pub fn outside_address(&self) -> &str {
        &self.outside_address
    }

    /// A command that runs `program` inside the namespace.
    pub fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut command = Command::new("ip");
        command.args(["netns", "exec", &self.name]).arg(program);
        command
    }

    /// Sets the link down (cut) or up (healed).
    pub fn set_link(&self, up: bool) -> Result<(), String> {
        ip(&args(&[
            "link",
            "set",
            &self.outside,
            if up { "up" } else { "down" },
        ]))
    }

    fn inside(&self, rest: &[&str]) -> Vec<String> {
        let mut all = args(&["-n", &self.name]);
        all.extend(args(rest));
        all
    }
}

impl Drop for Netns {
    fn drop(&mut self) {
        // Deleting the namespace deletes its end of the link, and with it ours.
        let _ = ip(&args(&["netns", "del", &self.name]));
    }
}

fn args(items: &[&str]) -> Vec<String> {
    items.iter().map(|item| item.to_string()).collect()
}

/// Runs `ip args`, or says what it printed.
fn ip(args: &[String]) -> Result<(), String> {
    let output = Command::new("ip")
        .args(args)
        .output()
        .map_err(|error| format!("ip {}: {error}", args.join(" ")))?;
    if output.status.success() {
        Ok(())
    } else {
        Err(format!(
            "ip {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&output.stderr).trim()
        ))
    }
}
