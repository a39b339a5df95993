//! The module tree of Shin 1985, §2: a module is the child of the module that created it, and
//! the traffic on a port is *vertical* between a module and one of its descendants,
//! *horizontal* otherwise.

use std::collections::BTreeMap;
use std::fmt;

use imrs_ports::{Name, Priority};

/// One running module, as the tree shows it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TreeModule {
    /// The module.
    pub name: Name,
    /// The module that costarted it; `None` for a top-level module.
    pub parent: Option<Name>,
    /// Its priority on its processor ([`ModuleSpec::priority`](crate::ModuleSpec::priority)).
    pub priority: Priority,
    /// The processor it runs on, if it shares one.
    pub processor: Option<Name>,
}

/// Which way the traffic on a port runs in the tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LinkKind {
    /// Between a module and one of its descendants.
    Vertical,
    /// Between modules neither of which descends from the other.
    Horizontal,
}

/// A port between its owner and one of its users, both running.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Link {
    /// The port.
    pub port: Name,
    /// The module that owns it.
    pub owner: Name,
    /// A module that uses it (or filters it).
    pub user: Name,
    /// Vertical or horizontal.
    pub kind: LinkKind,
}

/// The cell's modules as the seed draws them: the tree of who started whom, and every port
/// as a vertical or horizontal link. [`Cell::tree`](crate::Cell::tree) takes it; its
/// `Display` draws it.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ModuleTree {
    /// The running modules, by name.
    pub modules: Vec<TreeModule>,
    /// The links, by port, then owner, then user.
    pub links: Vec<Link>,
}

/// What the cell records of a module when it starts, for its tree.
#[derive(Debug, Clone)]
pub(crate) struct Placement {
    pub(crate) module: TreeModule,
    /// Ports it owns.
    pub(crate) owns: Vec<Name>,
    /// Ports it uses or filters.
    pub(crate) uses: Vec<Name>,
}

impl ModuleTree {
    /// The tree of `placements`: links join each port's owner to each of its users.
    pub(crate) fn of<'a>(placements: impl IntoIterator<Item = &'a Placement>) -> Self {
        let placements: Vec<&Placement> = placements.into_iter().collect();
        let mut modules: Vec<TreeModule> = placements.iter().map(|p| p.module.clone()).collect();
        modules.sort_by(|a, b| a.name.cmp(&b.name));
        let mut tree = ModuleTree {
            modules,
            links: Vec::new(),
        };
        let mut owners: BTreeMap<&Name, Vec<&Name>> = BTreeMap::new();
        for placement in &placements {
            for port in &placement.owns {
                owners.entry(port).or_default().push(&placement.module.name);
            }
        }
        for placement in &placements {
            for port in &placement.uses {
                for owner in owners.get(port).into_iter().flatten() {
                    let user = &placement.module.name;
                    let kind = if tree.descends(user, owner) || tree.descends(owner, user) {
                        LinkKind::Vertical
                    } else {
                        LinkKind::Horizontal
                    };
                    tree.links.push(Link {
                        port: port.clone(),
                        owner: (*owner).clone(),
                        user: user.clone(),
                        kind,
                    });
                }
            }
        }
        tree.links
            .sort_by(|a, b| (&a.port, &a.owner, &a.user).cmp(&(&b.port, &b.owner, &b.user)));
        tree
    }

    /// The module named `name`, if it runs.
    pub fn module(&self, name: &str) -> Option<&TreeModule> {
        self.modules
            .iter()
            .find(|module| module.name.as_str() == name)
    }

    /// The modules `parent` costarted, by name.
    pub fn children<'a>(&'a self, parent: &'a Name) -> impl Iterator<Item = &'a TreeModule> {
        self.modules
            .iter()
            .filter(move |module| module.parent.as_ref() == Some(parent))
    }

    /// Whether `module` descends from `ancestor` (is its child, grandchild, ...).
    pub fn descends(&self, module: &Name, ancestor: &Name) -> bool {
        let mut at = self.module(module.as_str());
        // The tree has no cycles (a child starts after its parent), but a bound keeps a
        // malformed tree from looping.
        for _ in 0..=self.modules.len() {
            let Some(parent) = at.and_then(|module| module.parent.as_ref()) else {
                return false;
            };
            if parent == ancestor {
                return true;
            }
            at = self.module(parent.as_str());
        }
        false
    }

    /// The links of `module`, as owner or user.
    pub fn links_of<'a>(&'a self, module: &'a Name) -> impl Iterator<Item = &'a Link> {
        self.links
            .iter()
            .filter(move |link| &link.owner == module || &link.user == module)
    }

    fn draw(
        &self,
        f: &mut fmt::Formatter<'_>,
        module: &TreeModule,
        indent: &str,
        last: bool,
    ) -> fmt::Result {
        let (branch, further) = if last {
            ("└─ ", "   ")
        } else {
            ("├─ ", "│  ")
        };
        write!(f, "{indent}{branch}{}", module.name)?;
        let (mut vertical, mut horizontal) = (0, 0);
        for link in self.links_of(&module.name) {
            match link.kind {
                LinkKind::Vertical => vertical += 1,
                LinkKind::Horizontal => horizontal += 1,
            }
        }
        write!(f, "  [{vertical} vertical, {horizontal} horizontal")?;
        if let Some(n) = module.priority.number() {
            write!(f, ", priority {n}")?;
        }
        if let Some(processor) = &module.processor {
            write!(f, ", on {processor}")?;
        }
        writeln!(f, "]")?;
        let children: Vec<&TreeModule> = self.children(&module.name).collect();
        let indent = format!("{indent}{further}");
        for (index, child) in children.iter().enumerate() {
            self.draw(f, child, &indent, index + 1 == children.len())?;
        }
        Ok(())
    }
}

impl fmt::Display for ModuleTree {
    /// The tree, one module a line with its count of vertical and horizontal links, then
    /// every link:
    ///
    /// ```text
    /// cell
    /// ├─ GATE  [1 vertical, 0 horizontal]
    /// │  └─ CONVEYOR  [1 vertical, 0 horizontal]
    /// └─ LOADER  [0 vertical, 1 horizontal]
    /// links:
    ///   GATE.MOVE  GATE <- CONVEYOR  vertical
    ///   SHARE_FEEDER  LOADER <- GATE  horizontal
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "cell")?;
        // A module whose parent has ended hangs from the cell, so that none is lost.
        let roots: Vec<&TreeModule> = self
            .modules
            .iter()
            .filter(|module| {
                module
                    .parent
                    .as_ref()
                    .is_none_or(|parent| self.module(parent.as_str()).is_none())
            })
            .collect();
        for (index, root) in roots.iter().enumerate() {
            self.draw(f, root, "", index + 1 == roots.len())?;
        }
        if self.links.is_empty() {
            return Ok(());
        }
        writeln!(f, "links (owner <- user):")?;
        let width = self
            .links
            .iter()
            .map(|link| link.port.as_str().chars().count())
            .max();
        let width = width.unwrap_or(0);
        for link in &self.links {
            let kind = match link.kind {
                LinkKind::Vertical => "vertical",
                LinkKind::Horizontal => "horizontal",
            };
            writeln!(
                f,
                "  {:<width$}  {} <- {}  {kind}",
                link.port.as_str(),
                link.owner,
                link.user
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn placed(name: &str, parent: Option<&str>, owns: &[&str], uses: &[&str]) -> Placement {
        Placement {
            module: TreeModule {
                name: name.into(),
                parent: parent.map(Name::from),
                priority: Priority::DEFAULT,
                processor: None,
            },
            owns: owns.iter().copied().map(Name::from).collect(),
            uses: uses.iter().copied().map(Name::from).collect(),
        }
    }

    #[test]
    fn a_grandchild_talking_to_its_grandparent_is_vertical_and_cousins_are_horizontal() {
        let placements = [
            placed("ROOT", None, &["DOWN"], &[]),
            placed("A", Some("ROOT"), &[], &[]),
            placed("A1", Some("A"), &["ACROSS"], &["DOWN"]),
            placed("B", Some("ROOT"), &[], &["ACROSS"]),
        ];
        let tree = ModuleTree::of(&placements);
        let kind = |port: &str| {
            tree.links
                .iter()
                .find(|link| link.port.as_str() == port)
                .map(|link| link.kind)
        };
        assert_eq!(kind("DOWN"), Some(LinkKind::Vertical));
        assert_eq!(kind("ACROSS"), Some(LinkKind::Horizontal));
        assert!(tree.descends(&"A1".into(), &"ROOT".into()));
        assert!(!tree.descends(&"B".into(), &"A".into()));
    }
}
