//! `beltrami reference` (hidden): the command-line reference, `docs/reference.md`, made
//! from the argument parser itself and the solver registry, so that it says what the
//! program accepts. `tests/reference.rs` fails when the file differs from this output.

use beltrami_core::{OptionKind, Solver};
use clap::{Arg, ArgAction, Args, Command, CommandFactory};

use super::Cli;

#[derive(Debug, Args)]
pub struct ReferenceArgs {}

pub fn run(_: &ReferenceArgs) -> anyhow::Result<()> {
    print!("{}", markdown());
    Ok(())
}

/// The whole reference: every visible command with its arguments, then every solver
/// with what it accepts and its options.
pub fn markdown() -> String {
    let cli = Cli::command();
    let mut out = String::from(
        "# Command-line reference\n\n\
         Made by `beltrami reference` from the program's own argument parser and solver \
         registry (`cargo run --release -- reference > docs/reference.md`; a test fails \
         when this file is out of date). The how-to pages explain each job: \
         [tutorial.md](tutorial.md).\n\n",
    );
    out.push_str(
        "Options of every command: `-q, --quiet` prints nothing but results and errors.\n\n",
    );
    out.push_str("Commands:");
    let commands: Vec<&Command> = cli.get_subcommands().filter(|c| !c.is_hide_set()).collect();
    for (k, command) in commands.iter().enumerate() {
        let separator = if k == 0 { " " } else { ", " };
        out.push_str(&format!(
            "{separator}[`{0}`](#beltrami-{0})",
            command.get_name()
        ));
    }
    out.push_str("; [solvers](#solvers).\n");
    for command in commands {
        out.push_str(&command_section(command));
    }
    out.push_str(
        "\n## Solvers\n\n\
         The solvers `param`, `qc`, `batch` and Python's `beltrami.solve` select by name \
         (`--solver NAME`); their options are set with `--option NAME=VALUE` \
         (`beltrami solvers --json` lists the same as JSON).\n",
    );
    for solver in beltrami::registry().iter() {
        out.push_str(&solver_section(solver));
    }
    out
}

/// One command: its description, usage and a table of its arguments.
fn command_section(command: &Command) -> String {
    let name = command.get_name();
    let about = command
        .get_long_about()
        .or(command.get_about())
        .map(|text| one_line(&text.to_string()))
        .unwrap_or_default();
    let mut usage = command.clone().bin_name(format!("beltrami {name}"));
    let usage = usage.render_usage().to_string();
    let usage = usage.trim_start_matches("Usage: ");
    let mut out = format!("\n## `beltrami {name}`\n\n{about}\n\n```\n{usage}\n```\n\n");
    out.push_str("| argument | default | description |\n|---|---|---|\n");
    for arg in command.get_arguments().filter(|a| shown(a)) {
        out.push_str(&format!(
            "| {} | {} | {} |\n",
            cell(&spelling(arg)),
            cell(&default(arg)),
            cell(&description(arg))
        ));
    }
    out
}

/// Whether `arg` belongs in the table: not hidden, not help, version or the global
/// `--quiet` (said once at the top).
fn shown(arg: &Arg) -> bool {
    !arg.is_hide_set()
        && !matches!(arg.get_action(), ArgAction::Help | ArgAction::Version)
        && arg.get_id() != "quiet"
}

/// How `arg` is written: `MESH`, `-o, --output <OUTPUT>`, `--json`.
fn spelling(arg: &Arg) -> String {
    let value = arg
        .get_value_names()
        .map(|names| {
            names
                .iter()
                .map(|n| format!("<{n}>"))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .unwrap_or_else(|| format!("<{}>", arg.get_id().as_str().to_uppercase()));
    if arg.is_positional() {
        return format!("`{}`", value.trim_matches(['<', '>']));
    }
    let takes_value = !matches!(
        arg.get_action(),
        ArgAction::SetTrue | ArgAction::SetFalse | ArgAction::Count
    );
    let mut names = Vec::new();
    if let Some(short) = arg.get_short() {
        names.push(format!("-{short}"));
    }
    if let Some(long) = arg.get_long() {
        names.push(format!("--{long}"));
    }
    let mut text = names.join(", ");
    if takes_value {
        text.push(' ');
        text.push_str(&value);
    }
    format!("`{text}`")
}

/// The default value(s) of `arg`, if any.
fn default(arg: &Arg) -> String {
    let values: Vec<String> = arg
        .get_default_values()
        .iter()
        .map(|v| v.to_string_lossy().into_owned())
        .collect();
    if values.is_empty() || matches!(arg.get_action(), ArgAction::SetTrue) {
        String::new()
    } else {
        format!("`{}`", values.join(" "))
    }
}

/// The help of `arg`, its possible values with theirs, and whether it is required.
fn description(arg: &Arg) -> String {
    let mut text = arg
        .get_long_help()
        .or(arg.get_help())
        .map(|h| one_line(&h.to_string()))
        .unwrap_or_default();
    let values: Vec<String> = arg
        .get_possible_values()
        .iter()
        .filter(|v| !v.is_hide_set())
        .map(|v| match v.get_help() {
            Some(help) => format!("`{}` ({})", v.get_name(), one_line(&help.to_string())),
            None => format!("`{}`", v.get_name()),
        })
        .collect();
    if !values.is_empty() && !matches!(arg.get_action(), ArgAction::SetTrue) {
        sentence(&mut text, &format!("One of: {}.", values.join(", ")));
    }
    if arg.is_required_set() && !arg.is_positional() {
        sentence(&mut text, "Required.");
    }
    text
}

/// Appends the sentence `more` to `text`, ending `text`'s last sentence first.
fn sentence(text: &mut String, more: &str) {
    if !text.is_empty() {
        if !text.ends_with('.') {
            text.push('.');
        }
        text.push(' ');
    }
    text.push_str(more);
}

/// A number as a person writes it: `1e-6` rather than `0.000001`.
fn number(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// One solver: its description, what it accepts and a table of its options.
fn solver_section(solver: &dyn Solver) -> String {
    let a = solver.accepts();
    let join = |list: Vec<&'static str>| {
        if list.is_empty() {
            "none".to_string()
        } else {
            list.iter()
                .map(|s| format!("`{s}`"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    let mut out = format!(
        "\n### `{}`\n\n{}.\n\n",
        solver.name(),
        one_line(solver.description())
    );
    for (what, list) in beltrami::catalog::accepted_kinds(&a) {
        out.push_str(&format!("- {what}: {}\n", join(list)));
    }
    if solver.options().is_empty() {
        return out;
    }
    out.push_str("\n| option | type | default | range | description |\n|---|---|---|---|---|\n");
    for spec in solver.options() {
        let (default, range) = match spec.kind {
            OptionKind::Float { default, min, max } => (
                number(default),
                format!("[{}, {}]", number(min), number(max)),
            ),
            OptionKind::Int { default, min, max } => {
                (default.to_string(), format!("[{min}, {max}]"))
            }
            OptionKind::Bool { default } => (default.to_string(), "true, false".to_string()),
            OptionKind::Choice { default, choices } => (default.to_string(), choices.join(", ")),
            OptionKind::Name { default } => (default.to_string(), "a name".to_string()),
        };
        out.push_str(&format!(
            "| `{}` | {} | `{}` | {} | {} |\n",
            spec.name,
            spec.kind.type_name(),
            default,
            cell(&range),
            cell(spec.help)
        ));
    }
    out
}

/// `text` on one line (paragraphs and wrapped lines joined by spaces).
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `text` fit for a table cell: pipes escaped.
fn cell(text: &str) -> String {
    one_line(text).replace('|', "\\|")
}
