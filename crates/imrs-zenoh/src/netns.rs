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
    /// Each `k` has a link and a /30 subnet of its own, found from this process's id. The
    /// namespaces of processes that have died without removing theirs are removed first.
    pub fn make(k: u8) -> Result<Self, String> {
        sweep_dead();
        let pid = std::process::id();
        let id = pid % 100_000;
        let (name, outside, inside) = (
            format!("imrs-{pid}-{k}"),
            format!("imrso{id}x{k}"),
            format!("imrsi{id}x{k}"),
        );
        // 16,384 subnets of four addresses for each `k`.
        let (third, base) = ((id >> 6) & 255, (id & 63) * 4);
        let at = |host: u32| format!("10.{}.{third}.{}", 100 + k % 100, base + host);
        // Nothing to remove if it cannot be made: it may be another's.
        ip(&args(&["netns", "add", &name]))?;
        let netns = Self {
            name: name.clone(),
            outside: outside.clone(),
            inside_address: at(2),
            outside_address: at(1),
        };
        let link = [
            "link", "add", &outside, "type", "veth", "peer", "name", &inside, "netns", &name,
        ];
        let steps: [Vec<String>; 6] = [
            args(&link),
            args(&["addr", "add", &format!("{}/30", at(1)), "dev", &outside]),
            args(&["link", "set", &outside, "up"]),
            netns.inside(&["addr", "add", &format!("{}/30", at(2)), "dev", &inside]),
            netns.inside(&["link", "set", &inside, "up"]),
            netns.inside(&["link", "set", "lo", "up"]),
        ];
        for step in steps {
            ip(&step)?;
        }
        Ok(netns)
    }

    /// The name of this namespace's end of the link, on this side.
    pub fn link(&self) -> &str {
        &self.outside
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

/// Removes the namespaces of this module's making (`imrs-<pid>-<k>`) whose process has died
/// without removing them (killed): their links would hold addresses a new one may need.
fn sweep_dead() {
    let Ok(listed) = Command::new("ip").args(["netns", "list"]).output() else {
        return;
    };
    for line in String::from_utf8_lossy(&listed.stdout).lines() {
        let name = line.split_whitespace().next().unwrap_or_default();
        let pid = name
            .strip_prefix("imrs-")
            .and_then(|rest| rest.split_once('-'))
            .and_then(|(pid, _)| pid.parse::<u32>().ok());
        if let Some(pid) = pid
            && !std::path::Path::new(&format!("/proc/{pid}")).exists()
        {
            let _ = ip(&args(&["netns", "del", name]));
        }
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
