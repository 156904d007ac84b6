//! The registered solvers as data: what each accepts and its options, for
//! `beltrami solvers --json`, scripts and the Python package.

use beltrami_core::{Accepts, GoalKind, OptionKind, Solver, TargetKind};
use serde_json::{Value, json};

/// One solver as JSON: `name`, `description`, `accepts` (`elements`, `topologies`,
/// `targets`, `goals`, `constraints`: arrays of the stable kind names of
/// [`beltrami_core::Accepts`]) and `options` (per option: `name`, `type`, `default`,
/// `min` and `max` for numbers, `choices` for choices, `help`).
pub fn solver_json(solver: &dyn Solver) -> Value {
    let a = solver.accepts();
    let options: Vec<Value> = solver
        .options()
        .iter()
        .map(|spec| {
            let mut o = json!({
                "name": spec.name,
                "type": spec.kind.type_name(),
                "help": spec.help,
            });
            match spec.kind {
                OptionKind::Float { default, min, max } => {
                    o["default"] = json!(default);
                    o["min"] = json!(min);
                    o["max"] = json!(max);
                }
                OptionKind::Int { default, min, max } => {
                    o["default"] = json!(default);
                    o["min"] = json!(min);
                    o["max"] = json!(max);
                }
                OptionKind::Bool { default } => o["default"] = json!(default),
                OptionKind::Choice { default, choices } => {
                    o["default"] = json!(default);
                    o["choices"] = json!(choices);
                }
                OptionKind::Name { default } => o["default"] = json!(default),
            }
            o
        })
        .collect();
    json!({
        "name": solver.name(),
        "description": solver.description(),
        "accepts": accepted_kinds(&a)
            .into_iter()
            .map(|(what, list)| (what.to_string(), json!(list)))
            .collect::<serde_json::Map<String, Value>>(),
        "options": options,
    })
}

/// What a solver accepts, kind by kind: `(what, names)` for its elements, topologies,
/// targets, goals and constraints, in that order.
pub fn accepted_kinds(a: &Accepts) -> [(&'static str, Vec<&'static str>); 5] {
    [
        ("elements", a.elements.iter().map(|e| e.name()).collect()),
        (
            "topologies",
            a.topologies.iter().map(|t| t.name()).collect(),
        ),
        ("targets", a.targets.iter().map(|t| t.name()).collect()),
        ("goals", a.goals.iter().map(|g| g.name()).collect()),
        (
            "constraints",
            a.constraints.iter().map(|c| c.name()).collect(),
        ),
    ]
}

/// One solver in text: its name and description, then one line per accepted kind list
/// and one per option (`name type = default [min, max]` or `{choices}`, help).
pub fn solver_text(solver: &dyn Solver) -> String {
    let a = solver.accepts();
    let join = |list: Vec<&'static str>| {
        if list.is_empty() {
            "none".to_string()
        } else {
            list.join(", ")
        }
    };
    let mut out = format!("{:<14} {}\n", solver.name(), solver.description());
    for (what, list) in accepted_kinds(&a) {
        out.push_str(&format!("{:<14} {what}: {}\n", "", join(list)));
    }
    for spec in solver.options() {
        let range = match spec.kind {
            OptionKind::Float { default, min, max } => format!("= {default} [{min}, {max}]"),
            OptionKind::Int { default, min, max } => format!("= {default} [{min}, {max}]"),
            OptionKind::Bool { default } => format!("= {default}"),
            OptionKind::Choice { default, choices } => {
                format!("= {default} {{{}}}", choices.join(", "))
            }
            OptionKind::Name { default } => format!("= {default}"),
        };
        out.push_str(&format!(
            "{:<14} option {} ({}) {range}: {}\n",
            "",
            spec.name,
            spec.kind.type_name(),
            spec.help
        ));
    }
    out
}

/// The registered solvers that map into a parameter domain (a target other than a
/// mesh or the source surface itself) and take `goal`, by name in the registry's order:
/// `param` lists those of the conformal goal, `qc` those of a prescribed coefficient or
/// an extremal map.
pub fn domain_solvers(goal: impl Fn(&[GoalKind]) -> bool) -> Vec<&'static str> {
    let onto_domain = |a: &Accepts| {
        a.targets
            .iter()
            .any(|t| !matches!(t, TargetKind::Mesh | TargetKind::Surface))
    };
    crate::registry()
        .iter()
        .filter(|solver| {
            let a = solver.accepts();
            onto_domain(&a) && goal(a.goals)
        })
        .map(|solver| solver.name())
        .collect()
}
