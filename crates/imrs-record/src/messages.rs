//! How the cell's events become messages: which channel each goes to, its JSON, and the JSON
//! schemas that let Foxglove show the fields.

use foxglove::messages::{Log, log::Level};
use std::time::Duration;

use imrs_core::{Event, EventKind, Observed};
use imrs_scene::{Fact, Field, Severity};
use serde_json::{Value, json};

use crate::time::stamp;

/// The schema of the messages on a port's channel, `/ports/PORT`.
pub(crate) const PORT_SCHEMA: &str = r#"{
  "title": "imrs.PortEvent",
  "description": "One primitive on a port, as the module that used it logged it",
  "type": "object",
  "properties": {
    "op": {"type": "string", "enum": ["send", "receive", "query", "response", "error"]},
    "module": {"type": "string"},
    "task": {"type": "string"},
    "waited_s": {"type": "number", "description": "how long the primitive waited"},
    "message": {"type": "string", "description": "the message, where the port shows its values"},
    "reply": {"type": "string", "description": "the reply, where the port shows its values"},
    "handler": {"type": "string"},
    "primitive": {"type": "string", "description": "the primitive that failed"},
    "error": {"type": "string"}
  },
  "required": ["op", "module"]
}"#;

/// The schema of the messages on a module's channel, `/modules/MODULE`.
pub(crate) const MODULE_SCHEMA: &str = r#"{
  "title": "imrs.ModuleEvent",
  "description": "A module's life: tasks, sections entered and left, exceptions, steps, alarms",
  "type": "object",
  "properties": {
    "event": {"type": "string"},
    "task": {"type": "string"},
    "section": {"type": "string"},
    "detail": {"type": "string"},
    "text": {"type": "string"}
  },
  "required": ["event", "text"]
}"#;

/// The schema of the simulation's measured facts, `/sim/events`.
pub(crate) const SIM_SCHEMA: &str = r#"{
  "title": "imrs.SimEvent",
  "description": "A fact measured by the simulation",
  "type": "object",
  "properties": {
    "kind": {"type": "string"},
    "robot": {"type": "string"},
    "line": {"type": "string"},
    "pallet": {"type": "integer"},
    "chip": {"type": "integer"},
    "chips": {"type": "integer"},
    "feeder": {"type": "integer"},
    "on_card_mm": {"type": "array", "items": {"type": "number"}},
    "point": {"type": "array", "items": {"type": "number"}},
    "text": {"type": "string"}
  },
  "required": ["kind", "text"]
}"#;

/// Where a cell event is recorded: on its port's channel, or its module's. Names are
/// interned, so a route is a key that costs no string per event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum Route {
    /// `/ports/PORT`.
    Port(&'static str),
    /// `/modules/MODULE`.
    Module(&'static str),
}

impl Route {
    /// The channel's topic, its schema, and the schema's name.
    pub(crate) fn channel(self) -> (String, &'static str, &'static str) {
        match self {
            Route::Port(port) => (format!("/ports/{port}"), PORT_SCHEMA, "imrs.PortEvent"),
            Route::Module(module) => (
                format!("/modules/{module}"),
                MODULE_SCHEMA,
                "imrs.ModuleEvent",
            ),
        }
    }
}

/// The channel and the JSON of a cell event.
pub(crate) fn cell_message(event: &Event) -> (Route, Value) {
    let task = event.task.as_ref().map(|task| task.as_str());
    let port = |op: &str, port: &'static str, observed: Option<&Observed>| {
        let mut message = json!({"op": op, "module": event.module.as_str()});
        if let Some(task) = task {
            message["task"] = task.into();
        }
        if let Some(observed) = observed {
            message["waited_s"] = observed.waited.as_secs_f64().into();
            if let Some(text) = &observed.message {
                message["message"] = text.as_str().into();
            }
            if let Some(text) = &observed.reply {
                message["reply"] = text.as_str().into();
            }
        }
        (Route::Port(port), message)
    };
    match &event.kind {
        EventKind::Sent { port: p, observed } => port("send", p.as_str(), observed.as_deref()),
        EventKind::Received { port: p, observed } => {
            port("receive", p.as_str(), observed.as_deref())
        }
        EventKind::Queried { port: p, observed } => port("query", p.as_str(), observed.as_deref()),
        EventKind::PortError {
            port: p,
            error,
            primitive,
            observed,
        } => {
            let (route, mut json) = port("error", p.as_str(), observed.as_deref());
            json["error"] = error.as_str().into();
            json["primitive"] = primitive.to_string().into();
            (route, json)
        }
        EventKind::Responded { handler } => {
            // A handler is named `PORT.NAME`: its message belongs with the port's.
            let on = handler
                .as_str()
                .rsplit_once('.')
                .map_or(handler.as_str(), |(port, _)| port);
            let (route, mut message) = port("response", on, None);
            message["handler"] = handler.as_str().into();
            (route, message)
        }
        kind => {
            let mut message = json!({"event": module_event(kind), "text": event.to_string()});
            if let Some(task) = task {
                message["task"] = task.into();
            }
            match kind {
                EventKind::SectionEntered { section } | EventKind::SectionLeft { section } => {
                    message["section"] = section.as_str().into();
                }
                EventKind::ExceptionRaised { exception }
                | EventKind::ExceptionHandled { exception }
                | EventKind::ExceptionUnhandled { exception } => {
                    message["detail"] = exception.as_str().into();
                }
                EventKind::Alarm { message: detail }
                | EventKind::ModuleFailed { reason: detail }
                | EventKind::TaskFailed { reason: detail }
                | EventKind::StepPerformed { step: detail } => {
                    message["detail"] = detail.as_str().into();
                }
                EventKind::StepFailed { step, error } => {
                    message["detail"] = format!("{step}: {error}").into();
                }
                _ => {}
            }
            (Route::Module(event.module.as_str()), message)
        }
    }
}

fn module_event(kind: &EventKind) -> &'static str {
    match kind {
        EventKind::ModuleStarted { .. } => "module_started",
        EventKind::ModuleFinished => "module_finished",
        EventKind::ModuleKilled => "module_killed",
        EventKind::ModuleFailed { .. } => "module_failed",
        EventKind::ModuleRestarted { .. } => "module_restarted",
        EventKind::TaskStarted => "task_started",
        EventKind::TaskFinished => "task_finished",
        EventKind::TaskFailed { .. } => "task_failed",
        EventKind::TaskRestarted { .. } => "task_restarted",
        EventKind::SectionEntered { .. } => "section_entered",
        EventKind::SectionLeft { .. } => "section_left",
        EventKind::ExceptionRaised { .. } => "exception_raised",
        EventKind::ExceptionHandled { .. } => "exception_handled",
        EventKind::ExceptionUnhandled { .. } => "exception_unhandled",
        EventKind::WaitForReleased { .. } => "waitfor_released",
        EventKind::StepPerformed { .. } => "step_performed",
        EventKind::StepFailed { .. } => "step_failed",
        EventKind::Deadlock { .. } => "deadlock",
        EventKind::Alarm { .. } => "alarm",
        _ => "other",
    }
}

/// The log entry of a cell event that an engineer should see in Foxglove's log panel:
/// exceptions, timeouts and other port failures, restarts, failures, deadlocks, alarms.
pub(crate) fn cell_log(event: &Event) -> Option<Log> {
    let level = match &event.kind {
        EventKind::ExceptionRaised { .. }
        | EventKind::PortError { .. }
        | EventKind::Alarm { .. }
        | EventKind::StepFailed { .. }
        | EventKind::TaskRestarted { .. }
        | EventKind::ModuleRestarted { .. } => Level::Warning,
        EventKind::ExceptionHandled { .. } | EventKind::ModuleKilled => Level::Info,
        EventKind::ExceptionUnhandled { .. }
        | EventKind::TaskFailed { .. }
        | EventKind::ModuleFailed { .. }
        | EventKind::Deadlock { .. } => Level::Error,
        _ => return None,
    };
    Some(log_entry(
        event.at.since_start(),
        level,
        event.to_string(),
        event.module.as_str(),
    ))
}

/// A line of Foxglove's log panel, from `name`, at `at` since the start of the cell's clock.
fn log_entry(at: Duration, level: Level, message: String, name: &str) -> Log {
    Log {
        timestamp: Some(stamp(at)),
        level: level as i32,
        message,
        name: name.to_string(),
        file: String::new(),
        line: 0,
    }
}

/// The JSON of a measured fact: its kind, its fields, and its text.
pub(crate) fn sim_message(fact: &Fact) -> Value {
    let mut message = json!({"kind": fact.kind, "text": fact.text});
    for (name, field) in &fact.fields {
        message[*name] = match field {
            Field::Text(text) => json!(text),
            Field::Count(count) => json!(count),
            Field::Numbers(numbers) => json!(numbers),
        };
    }
    message
}

/// The log entry of a measured fact an engineer should see: collisions and faults.
pub(crate) fn sim_log(fact: &Fact) -> Option<Log> {
    let level = match fact.severity? {
        Severity::Error => Level::Error,
        Severity::Warning => Level::Warning,
    };
    Some(log_entry(fact.at, level, fact.text.clone(), "simulation"))
}
