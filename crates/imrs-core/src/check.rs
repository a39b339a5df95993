//! The load-time check (Shin 1985, §3 and §5.1): everything the types could not show, for a
//! whole cell at once, each problem naming its module and port.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;

use imrs_ports::{Name, UsageKind, WireError, Wiring};

use crate::decl::{ModuleDecl, owned_by};
use crate::exception::Exception;

/// One wiring problem of a cell.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CellError {
    /// A port could not be declared or attached.
    Wire(WireError),
    /// Two modules share a name.
    DuplicateModule {
        /// The name.
        module: Name,
    },
    /// A declared port whose owner is not among the modules checked.
    NoOwner {
        /// The port.
        port: Name,
        /// The owner the port was declared with.
        declared_owner: Name,
    },
    /// A module uses or filters a port that was never declared to the cell.
    UnknownPort {
        /// The port.
        port: Name,
        /// The module.
        module: Name,
    },
    /// A module uses a port whose user list does not name it.
    NotOnUserList {
        /// The port.
        port: Name,
        /// The module.
        module: Name,
    },
    /// More modules use a port than its number of active users allows.
    TooManyUsers {
        /// The port.
        port: Name,
        /// The allowed number.
        capacity: usize,
        /// Every module that uses it.
        modules: Vec<Name>,
    },
    /// A user's usage does not complement the owner's (or, on a filtered port, the filter's).
    UsageMismatch {
        /// The port.
        port: Name,
        /// The user module.
        module: Name,
        /// The usage it must complement.
        owner: UsageKind,
        /// The user's usage.
        user: UsageKind,
    },
    /// A filter declares a usage toward the users that the port was not declared with.
    FilterUsageMismatch {
        /// The port.
        port: Name,
        /// The module whose task filters it.
        module: Name,
        /// The filter's declared usage.
        filter: UsageKind,
        /// The usage the port's users side was declared with.
        declared: UsageKind,
    },
    /// An exception handler for an exception the module cannot raise: no port or barrier
    /// of it times out under that name, no task of it fails under it, and the module does
    /// not declare that it raises it.
    UnknownException {
        /// The module.
        module: Name,
        /// The handler's exception name.
        exception: Name,
    },
    /// A response handler named after one port, on the end of another.
    HandlerOnWrongPort {
        /// The module.
        module: Name,
        /// The handler's name (`PORT.resp`).
        handler: Name,
        /// The port its end answers.
        port: Name,
    },
    /// A module holds a response end on a port it neither owns nor uses.
    UndeclaredPort {
        /// The module.
        module: Name,
        /// The port.
        port: Name,
    },
    /// A handler of the module (a response or an exception handler) that its order does not
    /// rank: it would run at any suspension point, whatever section the module is in.
    Unranked {
        /// The module.
        module: Name,
        /// The handler (`PORT.resp`, `PORT.TIMEOUT`, `TASK.FAILED`, ...).
        handler: Name,
    },
    /// An order names something the module does not have.
    UnknownOrderName {
        /// The module.
        module: Name,
        /// The name in its order.
        name: Name,
    },
}

impl fmt::Display for CellError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Wire(error) => write!(f, "{error}"),
            Self::DuplicateModule { module } => write!(f, "two modules are named {module}"),
            Self::NoOwner {
                port,
                declared_owner,
            } => write!(
                f,
                "port {port} has no owner: its owner {declared_owner} is not among the modules"
            ),
            Self::UnknownPort { port, module } => {
                write!(
                    f,
                    "module {module} names port {port}, which is not declared"
                )
            }
            Self::NotOnUserList { port, module } => {
                write!(f, "module {module} is not on the user list of port {port}")
            }
            Self::TooManyUsers {
                port,
                capacity,
                modules,
            } => {
                write!(
                    f,
                    "port {port} allows {capacity} user(s), but {} use it:",
                    modules.len()
                )?;
                modules.iter().try_for_each(|module| write!(f, " {module}"))
            }
            Self::UsageMismatch {
                port,
                module,
                owner,
                user,
            } => write!(
                f,
                "module {module} uses port {port} with USAGE={user}, which does not complement USAGE={owner}"
            ),
            Self::FilterUsageMismatch {
                port,
                module,
                filter,
                declared,
            } => write!(
                f,
                "module {module} filters port {port} with USAGE={filter}, but the port is declared USAGE={declared}"
            ),
            Self::UnknownException { module, exception } => write!(
                f,
                "module {module} handles exception {exception}, which it cannot raise: no port \
                 or task of it has that name, and it does not declare it in `raises`"
            ),
            Self::HandlerOnWrongPort {
                module,
                handler,
                port,
            } => write!(
                f,
                "module {module} names its response handler {handler}, but its end answers port {port} (name it {port}.<resp>)"
            ),
            Self::UndeclaredPort { module, port } => write!(
                f,
                "module {module} answers queries on port {port}, which it neither owns nor uses"
            ),
            Self::Unranked { module, handler } => write!(
                f,
                "module {module} has a handler {handler} that its order does not rank: put it \
                 in the order, where it may start"
            ),
            Self::UnknownOrderName { module, name } => write!(
                f,
                "the order of module {module} names {name}, which is not a handler or an exception of it"
            ),
        }
    }
}

impl std::error::Error for CellError {}

/// Every wiring problem of a cell.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CellErrors(pub Vec<CellError>);

impl fmt::Display for CellErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} wiring problem(s):", self.0.len())?;
        self.0
            .iter()
            .try_for_each(|problem| writeln!(f, "  - {problem}"))
    }
}

impl std::error::Error for CellErrors {}

impl From<CellError> for CellErrors {
    fn from(error: CellError) -> Self {
        Self(vec![error])
    }
}

impl From<WireError> for CellErrors {
    fn from(error: WireError) -> Self {
        Self(vec![CellError::Wire(error)])
    }
}

pub(crate) fn check(wiring: &Wiring, modules: &[ModuleDecl]) -> Result<(), CellErrors> {
    // What went wrong when ports were declared or attached by name, earlier.
    let mut problems: Vec<CellError> = match wiring.check() {
        Ok(()) => Vec::new(),
        Err(earlier) => earlier.0.into_iter().map(CellError::Wire).collect(),
    };
    let mut seen = BTreeSet::new();
    for module in modules {
        if !seen.insert(&module.name) {
            problems.push(CellError::DuplicateModule {
                module: module.name.clone(),
            });
        }
    }
    check_owners(wiring, modules, &mut problems);
    check_users(wiring, modules, &mut problems);
    check_filters(wiring, modules, &mut problems);
    for module in modules {
        check_itself(wiring, module, &mut problems);
    }
    into_result(problems)
}

/// The check of one module as it starts: everything the whole cell's check finds that lies
/// in this module alone.
pub(crate) fn check_module(wiring: &Wiring, module: &ModuleDecl) -> Result<(), CellErrors> {
    let mut problems = Vec::new();
    let module = std::slice::from_ref(module);
    check_users(wiring, module, &mut problems);
    check_filters(wiring, module, &mut problems);
    check_itself(wiring, &module[0], &mut problems);
    into_result(problems)
}

fn into_result(problems: Vec<CellError>) -> Result<(), CellErrors> {
    if problems.is_empty() {
        Ok(())
    } else {
        Err(CellErrors(problems))
    }
}

/// What a module's declaration says of itself: its ends, order, handlers and exceptions.
fn check_itself(wiring: &Wiring, module: &ModuleDecl, problems: &mut Vec<CellError>) {
    problems.extend(module.problems.iter().cloned().map(CellError::Wire));
    let owns = owned_by(wiring, &module.name);
    check_order(module, &owns, problems);
    check_ranked(module, problems);
    check_exceptions(module, &owns, problems);
    check_responses(module, &owns, problems);
}

/// Every declared port's owner is among the modules (or runs in another process).
fn check_owners(wiring: &Wiring, modules: &[ModuleDecl], problems: &mut Vec<CellError>) {
    let present: BTreeSet<&Name> = modules.iter().map(|module| &module.name).collect();
    for port in wiring.port_names() {
        let info = wiring
            .port_info(port.as_str())
            .expect("a listed port has info");
        if !present.contains(&info.owner) && !wiring.owned_elsewhere(port.as_str()) {
            problems.push(CellError::NoOwner {
                port: port.clone(),
                declared_owner: info.owner,
            });
        }
    }
}

fn check_users(wiring: &Wiring, modules: &[ModuleDecl], problems: &mut Vec<CellError>) {
    let mut users: BTreeMap<&Name, Vec<Name>> = BTreeMap::new();
    for module in modules {
        for (port, usage) in &module.uses {
            let Some(info) = wiring.port_info(port.as_str()) else {
                problems.push(CellError::UnknownPort {
                    port: port.clone(),
                    module: module.name.clone(),
                });
                continue;
            };
            users.entry(port).or_default().push(module.name.clone());
            let listed = info
                .user_list
                .as_ref()
                .is_none_or(|list| list.contains(&module.name));
            if !listed {
                problems.push(CellError::NotOnUserList {
                    port: port.clone(),
                    module: module.name.clone(),
                });
            }
            if !info.usage.complements(*usage) {
                problems.push(CellError::UsageMismatch {
                    port: port.clone(),
                    module: module.name.clone(),
                    owner: info.usage,
                    user: *usage,
                });
            }
        }
    }
    for (port, modules) in users {
        let info = wiring.port_info(port.as_str()).expect("checked above");
        if modules.len() > info.capacity {
            problems.push(CellError::TooManyUsers {
                port: port.clone(),
                capacity: info.capacity,
                modules,
            });
        }
    }
}

fn check_filters(wiring: &Wiring, modules: &[ModuleDecl], problems: &mut Vec<CellError>) {
    for module in modules {
        for (port, usage) in &module.filters {
            let Some(info) = wiring.port_info(port.as_str()) else {
                problems.push(CellError::UnknownPort {
                    port: port.clone(),
                    module: module.name.clone(),
                });
                continue;
            };
            if info.usage != *usage {
                problems.push(CellError::FilterUsageMismatch {
                    port: port.clone(),
                    module: module.name.clone(),
                    filter: *usage,
                    declared: info.usage,
                });
            }
        }
    }
}

/// The ports a module owns, uses or filters.
fn ports_of<'a>(module: &'a ModuleDecl, owns: &'a [Name]) -> impl Iterator<Item = &'a Name> {
    owns.iter()
        .chain(module.uses.iter().map(|(port, _)| port))
        .chain(module.filters.iter().map(|(port, _)| port))
}

/// Every exception module can raise: its ports' timeouts, its tasks' failures, and those it
/// declares.
fn raisable(module: &ModuleDecl, owns: &[Name]) -> BTreeSet<Name> {
    let mut raisable: BTreeSet<Name> = ports_of(module, owns)
        .map(|port| Exception::timeout_of(port.as_str()))
        .collect();
    raisable.extend(
        module
            .tasks
            .iter()
            .map(|task| Exception::failure_of(task.as_str())),
    );
    raisable.extend(module.raises.iter().cloned());
    raisable
}

fn check_exceptions(module: &ModuleDecl, owns: &[Name], problems: &mut Vec<CellError>) {
    let raisable = raisable(module, owns);
    for exception in &module.exceptions {
        if !raisable.contains(exception) {
            problems.push(CellError::UnknownException {
                module: module.name.clone(),
                exception: exception.clone(),
            });
        }
    }
}

fn check_responses(module: &ModuleDecl, owns: &[Name], problems: &mut Vec<CellError>) {
    let declared: BTreeSet<&Name> = owns
        .iter()
        .chain(module.uses.iter().map(|(port, _)| port))
        .collect();
    for (handler, port) in &module.responses {
        let named_port = handler.as_str().split_once('.').map(|(port, _)| port);
        if named_port != Some(port.as_str()) {
            problems.push(CellError::HandlerOnWrongPort {
                module: module.name.clone(),
                handler: handler.clone(),
                port: port.clone(),
            });
        }
        if !declared.contains(port) {
            problems.push(CellError::UndeclaredPort {
                module: module.name.clone(),
                port: port.clone(),
            });
        }
    }
}

/// Every handler, response or exception, is in the order: one left out would run wherever
/// the module is, which is the order's whole point to decide.
fn check_ranked(module: &ModuleDecl, problems: &mut Vec<CellError>) {
    let ranked: BTreeSet<&Name> = module.order.iter().collect();
    let handlers = module
        .responses
        .iter()
        .map(|(handler, _)| handler)
        .chain(&module.exceptions);
    for handler in handlers {
        if !ranked.contains(handler) {
            problems.push(CellError::Unranked {
                module: module.name.clone(),
                handler: handler.clone(),
            });
        }
    }
}

/// The order names nothing that looks like a handler (`X.Y`) the module does not have; a
/// plain name other than the module's own is a named section.
fn check_order(module: &ModuleDecl, owns: &[Name], problems: &mut Vec<CellError>) {
    let mut known = raisable(module, owns);
    known.extend(module.responses.iter().map(|(handler, _)| handler.clone()));
    known.extend(module.exceptions.iter().cloned());
    for name in &module.order {
        if name.as_str().contains('.') && !known.contains(name) {
            problems.push(CellError::UnknownOrderName {
                module: module.name.clone(),
                name: name.clone(),
            });
        }
    }
}
