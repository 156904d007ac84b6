//! The jobs file of `beltrami batch`: one JSON object per line, each a command line.
//!
//! ```text
//! {"command": "param", "input": "a.obj", "output": "a_uv.obj", "options": {"solver": "lscm"}}
//! {"command": "register", "input": ["face_a.obj", "face_b.obj"], "output": "a_on_b.obj"}
//! ```
//!
//! Blank lines and lines starting with `#` are skipped; a UTF-8 byte-order mark at the
//! start is ignored. `input` is the command's positional argument or list of them,
//! `output` its `-o`, and each `options` entry a flag: `"name": value` is
//! `--name value`, `true` is `--name` alone, `false` omits it, and an array repeats the
//! flag (`"pin": ["v0", "v9"]`). Nothing a line holds can become another flag than its
//! own option names: values and paths that start like a flag are refused.

use std::fmt;
use std::path::PathBuf;

use serde_json::Value;
use thiserror::Error;

/// The commands a job may run.
pub const COMMANDS: &[&str] = &["param", "qc", "register", "remesh"];

/// One job of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// 1-based line of the jobs file.
    pub line: usize,
    /// `param`, `qc`, `register` or `remesh`.
    pub command: String,
    /// The output path (`-o`).
    pub output: PathBuf,
    /// The arguments after the program name: the command, its inputs, `-o OUTPUT`, then
    /// the options' flags.
    pub args: Vec<String>,
}

/// A line of the jobs file that is not a job, and why.
#[derive(Debug)]
pub struct JobError {
    /// 1-based line of the jobs file.
    pub line: usize,
    /// What is wrong with it.
    pub problem: JobProblem,
}

impl fmt::Display for JobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.problem)
    }
}

impl std::error::Error for JobError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        std::error::Error::source(&self.problem)
    }
}

/// What is wrong with a line of the jobs file.
#[derive(Debug, Error)]
pub enum JobProblem {
    /// The line is not JSON.
    #[error("not a JSON object")]
    NotJson(#[source] serde_json::Error),
    /// The line is JSON but not an object.
    #[error("not a JSON object")]
    NotAnObject,
    /// No `command` string.
    #[error("no \"command\" (one of {commands})", commands = COMMANDS.join(", "))]
    NoCommand,
    /// A command batch does not run.
    #[error("the command \"{0}\" is not one of {commands}", commands = COMMANDS.join(", "))]
    UnknownCommand(String),
    /// No `output` string.
    #[error("no \"output\" path")]
    NoOutput,
    /// An input or output path that the command would read as a flag.
    #[error("{what} \"{path}\" starts with `-`, which the command would read as a flag")]
    DashedPath {
        /// `the input` or `the output`.
        what: &'static str,
        /// The path as written.
        path: String,
    },
    /// An `input` list with something other than a string.
    #[error("\"input\" holds a non-string {0}")]
    NonStringInput(Value),
    /// No `input` string or list.
    #[error("no \"input\" (a path or a list of paths)")]
    NoInput,
    /// A key other than command, input, output, options.
    #[error("unknown key \"{0}\" (command, input, output, options)")]
    UnknownKey(String),
    /// `options` that is not an object.
    #[error("\"options\" is not an object")]
    OptionsNotObject,
    /// An option name that is not a job option: help, version, the output, or a name
    /// that is empty, starts with `-` or holds `=` or white space.
    #[error(
        "\"{0}\" is not a job option (the output is the job's \"output\"; help and version are not jobs)"
    )]
    NotAnOption(String),
    /// An option value that the command would read as a flag.
    #[error("option \"{name}\" has the value \"{value}\", which the command would read as a flag")]
    FlagValue {
        /// The option.
        name: String,
        /// Its value.
        value: String,
    },
    /// An option value that is not a string, number, boolean or a list of those.
    #[error("option \"{name}\" has the value {value}")]
    BadValue {
        /// The option.
        name: String,
        /// Its value.
        value: Value,
    },
}

/// The jobs of a jobs file's text (module docs), or the first line that is not a job.
pub fn parse_jobs(text: &str) -> Result<Vec<Job>, JobError> {
    // Editors on Windows start UTF-8 files with a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|(i, l)| parse_job(i + 1, l))
        .collect()
}

/// The job of line `line` of the jobs file, whose text is `text` (module docs).
pub fn parse_job(line: usize, text: &str) -> Result<Job, JobError> {
    parse_object(line, text).map_err(|problem| JobError { line, problem })
}

/// [`parse_job`], its errors without the line number.
fn parse_object(line: usize, text: &str) -> Result<Job, JobProblem> {
    let value: Value = serde_json::from_str(text).map_err(JobProblem::NotJson)?;
    let object = value.as_object().ok_or(JobProblem::NotAnObject)?;
    let command = object
        .get("command")
        .and_then(Value::as_str)
        .ok_or(JobProblem::NoCommand)?;
    if !COMMANDS.contains(&command) {
        return Err(JobProblem::UnknownCommand(command.to_string()));
    }
    let output = object
        .get("output")
        .and_then(Value::as_str)
        .ok_or(JobProblem::NoOutput)?;
    not_dashed("the output", output)?;
    let inputs: Vec<String> = match object.get("input") {
        Some(Value::String(s)) => vec![s.clone()],
        Some(Value::Array(items)) => items
            .iter()
            .map(|v| {
                v.as_str()
                    .map(str::to_string)
                    .ok_or_else(|| JobProblem::NonStringInput(v.clone()))
            })
            .collect::<Result<_, _>>()?,
        _ => return Err(JobProblem::NoInput),
    };
    for input in &inputs {
        not_dashed("the input", input)?;
    }
    if let Some(key) = object
        .keys()
        .find(|k| !["command", "input", "output", "options"].contains(&k.as_str()))
    {
        return Err(JobProblem::UnknownKey(key.clone()));
    }
    let mut args = vec![command.to_string()];
    args.extend(inputs);
    args.extend(["-o".to_string(), output.to_string()]);
    if let Some(options) = object.get("options") {
        let options = options.as_object().ok_or(JobProblem::OptionsNotObject)?;
        for (name, value) in options {
            push_option(&mut args, name, value)?;
        }
    }
    Ok(Job {
        line,
        command: command.to_string(),
        output: PathBuf::from(output),
        args,
    })
}

/// Refuses a path that the command would read as a flag.
fn not_dashed(what: &'static str, path: &str) -> Result<(), JobProblem> {
    if path.starts_with('-') {
        return Err(JobProblem::DashedPath {
            what,
            path: path.to_string(),
        });
    }
    Ok(())
}

/// Appends the flags of option `name` with `value` (module docs) to `args`.
fn push_option(args: &mut Vec<String>, name: &str, value: &Value) -> Result<(), JobProblem> {
    // `--` would end the command's flags, `--output=x` would set another output.
    let malformed =
        name.is_empty() || name.starts_with('-') || name.contains(['=', ' ', '\t', '\n', '\r']);
    if malformed || matches!(name, "help" | "version" | "output" | "o") {
        return Err(JobProblem::NotAnOption(name.to_string()));
    }
    let flag = format!("--{name}");
    let items = match value {
        Value::Array(items) => items.as_slice(),
        other => std::slice::from_ref(other),
    };
    for item in items {
        match item {
            Value::Bool(true) => args.push(flag.clone()),
            Value::Bool(false) => {}
            Value::String(s) if s.starts_with("--") => {
                return Err(JobProblem::FlagValue {
                    name: name.to_string(),
                    value: s.clone(),
                });
            }
            Value::String(s) => args.extend([flag.clone(), s.clone()]),
            Value::Number(n) => args.extend([flag.clone(), n.to_string()]),
            other => {
                return Err(JobProblem::BadValue {
                    name: name.to_string(),
                    value: other.clone(),
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_job_line_becomes_the_command_line() {
        let job = parse_job(
            3,
            r#"{"command": "param", "input": "a.obj", "output": "b.obj", "options": {"solver": "tutte", "pin": ["v0", "v4"], "json": false, "repair": true, "tolerance": 1e-6}}"#,
        )
        .unwrap();
        assert_eq!(job.line, 3);
        assert_eq!(job.output, PathBuf::from("b.obj"));
        assert_eq!(
            job.args,
            [
                "param",
                "a.obj",
                "-o",
                "b.obj",
                "--pin",
                "v0",
                "--pin",
                "v4",
                "--repair",
                "--solver",
                "tutte",
                "--tolerance",
                "1e-6"
            ]
        );
        let two = parse_job(
            1,
            r#"{"command": "register", "input": ["s.obj", "t.obj"], "output": "o.obj"}"#,
        )
        .unwrap();
        assert_eq!(two.args, ["register", "s.obj", "t.obj", "-o", "o.obj"]);
    }

    #[test]
    fn bad_lines_are_named() {
        for (text, expected) in [
            ("[1, 2]", "line 7: not a JSON object"),
            ("{\"command\": ", "line 7: not a JSON object"),
            (
                "{\"command\": \"render\", \"input\": \"a\", \"output\": \"b\"}",
                "\"render\" is not one of",
            ),
            ("{\"command\": \"qc\", \"input\": \"a\"}", "no \"output\""),
            ("{\"command\": \"qc\", \"output\": \"b\"}", "no \"input\""),
            (
                "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"extra\": 1}",
                "unknown key \"extra\"",
            ),
            (
                "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"options\": {\"mu\": null}}",
                "option \"mu\"",
            ),
            (
                "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"options\": {\"\": true}}",
                "\"\" is not a job option",
            ),
            (
                "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"options\": {\"output=c\": \"x\"}}",
                "\"output=c\" is not a job option",
            ),
            (
                "{\"command\": \"qc\", \"input\": \"-a\", \"output\": \"b\"}",
                "the input \"-a\" starts with `-`",
            ),
            (
                "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"options\": {\"solver\": \"--json\"}}",
                "which the command would read as a flag",
            ),
        ] {
            let error = parse_job(7, text).unwrap_err();
            assert_eq!(error.line, 7);
            assert!(error.to_string().contains(expected), "{text}: {error}");
        }
    }

    #[test]
    fn a_file_skips_blank_and_comment_lines_and_names_the_bad_one() {
        let job = r#"{"command": "qc", "input": "a", "output": "b"}"#;
        let text = format!("\u{feff}{job}\n\n  # a comment\n{job}\n");
        let jobs = parse_jobs(&text).unwrap();
        assert_eq!(jobs.iter().map(|j| j.line).collect::<Vec<_>>(), [1, 4]);
        let error = parse_jobs(&format!("{job}\n# fine\n[]\n")).unwrap_err();
        assert_eq!(error.line, 3);
    }
}
