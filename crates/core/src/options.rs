//! Typed solver options: each solver declares its settings ([`OptionSpec`]: name, type,
//! default, range, one line of help); a problem carries the values a user set
//! ([`Options`]); [`Settings::resolve`] checks them against the declarations once,
//! before any work, and fills in the defaults.
//!
//! Names are kebab-case (`max-iters`, `tolerance`), the same on the command line
//! (`--option name=value`), in `beltrami solvers --json` and in Python.

use std::fmt;

use thiserror::Error;

/// The type, default and admissible values of an option.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OptionKind {
    /// A real number in `[min, max]` (finite).
    Float {
        /// The default.
        default: f64,
        /// The least admissible value.
        min: f64,
        /// The largest admissible value.
        max: f64,
    },
    /// A whole number in `[min, max]`.
    Int {
        /// The default.
        default: usize,
        /// The least admissible value.
        min: usize,
        /// The largest admissible value.
        max: usize,
    },
    /// A flag.
    Bool {
        /// The default.
        default: bool,
    },
    /// One of a list of names.
    Choice {
        /// The default (one of `choices`).
        default: &'static str,
        /// The admissible names.
        choices: &'static [&'static str],
    },
    /// A name from a list only known when the solver runs (another registered solver's
    /// name): any text passes [`Settings::resolve`], and the solver's own check refuses
    /// a name it does not know.
    Name {
        /// The default.
        default: &'static str,
    },
}

impl OptionKind {
    /// The type's name in listings: `float`, `int`, `bool`, `choice` or `name`.
    pub fn type_name(&self) -> &'static str {
        match self {
            OptionKind::Float { .. } => "float",
            OptionKind::Int { .. } => "int",
            OptionKind::Bool { .. } => "bool",
            OptionKind::Choice { .. } => "choice",
            OptionKind::Name { .. } => "name",
        }
    }

    /// What a value must be, in words for messages: "a number", "a whole number from 1
    /// to 100", "true or false", "one of a, b", "a name".
    pub fn expected(&self) -> String {
        match self {
            OptionKind::Float { .. } => "a number".to_string(),
            OptionKind::Int { min, max, .. } => format!("a whole number from {min} to {max}"),
            OptionKind::Bool { .. } => "true or false".to_string(),
            OptionKind::Choice { choices, .. } => format!("one of {}", choices.join(", ")),
            OptionKind::Name { .. } => "a name".to_string(),
        }
    }

    /// The default value.
    pub fn default_value(&self) -> OptionValue {
        match *self {
            OptionKind::Float { default, .. } => OptionValue::Float(default),
            OptionKind::Int { default, .. } => OptionValue::Int(default),
            OptionKind::Bool { default } => OptionValue::Bool(default),
            OptionKind::Choice { default, .. } | OptionKind::Name { default } => {
                OptionValue::Choice(default.to_string())
            }
        }
    }
}

/// One declared option of a solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptionSpec {
    /// The kebab-case name.
    pub name: &'static str,
    /// Type, default and range.
    pub kind: OptionKind,
    /// One line of help.
    pub help: &'static str,
}

/// A value of an option.
#[derive(Debug, Clone, PartialEq)]
pub enum OptionValue {
    /// A real number.
    Float(f64),
    /// A whole number.
    Int(usize),
    /// A flag.
    Bool(bool),
    /// A name (of a choice or a name option).
    Choice(String),
}

impl fmt::Display for OptionValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OptionValue::Float(x) => write!(f, "{x}"),
            OptionValue::Int(n) => write!(f, "{n}"),
            OptionValue::Bool(b) => write!(f, "{b}"),
            OptionValue::Choice(s) => f.write_str(s),
        }
    }
}

/// Why an option value was refused; every variant names the solver and the option.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OptionError {
    /// No option of that name.
    #[error("{solver} has no option `{option}`; its options: {known}")]
    Unknown {
        /// The solver.
        solver: &'static str,
        /// The name given.
        option: String,
        /// The declared names, comma-separated (`none` if there are none).
        known: String,
    },
    /// A value of the wrong type (a word for a number, a fraction for a whole number).
    #[error("{solver}: option `{option}` takes {expected}, got `{got}`")]
    Type {
        /// The solver.
        solver: &'static str,
        /// The option.
        option: &'static str,
        /// What the declared type admits, in words ([`OptionKind::expected`]).
        expected: String,
        /// The value given.
        got: String,
    },
    /// A number outside the declared range.
    #[error("{solver}: option `{option}` must lie in [{min}, {max}], got {got}")]
    Range {
        /// The solver.
        solver: &'static str,
        /// The option.
        option: &'static str,
        /// The least admissible value.
        min: String,
        /// The largest admissible value.
        max: String,
        /// The value given.
        got: String,
    },
    /// A name outside the declared choices.
    #[error("{solver}: option `{option}` is one of {choices}, got `{got}` ({help})")]
    Choice {
        /// The solver.
        solver: &'static str,
        /// The option.
        option: &'static str,
        /// The admissible names, comma-separated.
        choices: String,
        /// The name given.
        got: String,
        /// The option's help line.
        help: &'static str,
    },
}

/// The option values a user set, by name, in the order set (a later value of the same
/// name replaces the earlier one).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Options {
    values: Vec<(String, OptionValue)>,
}

impl Options {
    /// No values set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets option `name` to `value`.
    pub fn set(&mut self, name: &str, value: OptionValue) -> &mut Self {
        self.values.retain(|(n, _)| n != name);
        self.values.push((name.to_string(), value));
        self
    }

    /// Sets option `name` from text, typed later against the solver's declaration
    /// ([`Settings::resolve`] parses it as the declared type).
    pub fn set_text(&mut self, name: &str, text: &str) -> &mut Self {
        self.set(name, OptionValue::Choice(text.to_string()))
    }

    /// The value set for `name`, if any.
    pub fn get(&self, name: &str) -> Option<&OptionValue> {
        self.values.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    /// Every value set, in order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &OptionValue)> {
        self.values.iter().map(|(n, v)| (n.as_str(), v))
    }

    /// True if nothing was set.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

/// Every declared option of a solver with its value (set or default), checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    solver: &'static str,
    values: Vec<(&'static OptionSpec, OptionValue)>,
}

impl Settings {
    /// Checks the `given` values against `specs` (names, types, ranges, choices) and
    /// fills in the defaults. Text values (from [`Options::set_text`]) are parsed as the
    /// declared type; an integer is accepted where a float is declared.
    pub fn resolve(
        solver: &'static str,
        specs: &'static [OptionSpec],
        given: &Options,
    ) -> Result<Self, OptionError> {
        for (name, _) in given.iter() {
            if !specs.iter().any(|s| s.name == name) {
                let known: Vec<&str> = specs.iter().map(|s| s.name).collect();
                return Err(OptionError::Unknown {
                    solver,
                    option: name.to_string(),
                    known: if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    },
                });
            }
        }
        let values = specs
            .iter()
            .map(|spec| {
                let value = match given.get(spec.name) {
                    None => spec.kind.default_value(),
                    Some(v) => check(solver, spec, v)?,
                };
                Ok((spec, value))
            })
            .collect::<Result<_, OptionError>>()?;
        Ok(Self { solver, values })
    }

    /// The solver these settings are for.
    pub fn solver(&self) -> &'static str {
        self.solver
    }

    /// Every option with its value, in declaration order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static OptionSpec, &OptionValue)> {
        self.values.iter().map(|(s, v)| (*s, v))
    }

    fn value(&self, name: &str) -> &OptionValue {
        match self.values.iter().find(|(s, _)| s.name == name) {
            Some((_, v)) => v,
            // Names passed here are the solver's own constants, declared in its specs;
            // a miss is a bug in the solver, caught by its tests.
            None => panic!("{}: option `{name}` is not declared", self.solver),
        }
    }

    /// The value of a declared float option.
    ///
    /// # Panics
    /// If `name` is not a declared float option of the solver (a bug in the solver).
    pub fn float(&self, name: &str) -> f64 {
        match self.value(name) {
            OptionValue::Float(x) => *x,
            other => panic!("{}: option `{name}` is {other:?}, not a float", self.solver),
        }
    }

    /// The value of a declared int option.
    ///
    /// # Panics
    /// If `name` is not a declared int option of the solver (a bug in the solver).
    pub fn int(&self, name: &str) -> usize {
        match self.value(name) {
            OptionValue::Int(n) => *n,
            other => panic!("{}: option `{name}` is {other:?}, not an int", self.solver),
        }
    }

    /// The value of a declared bool option.
    ///
    /// # Panics
    /// If `name` is not a declared bool option of the solver (a bug in the solver).
    pub fn flag(&self, name: &str) -> bool {
        match self.value(name) {
            OptionValue::Bool(b) => *b,
            other => panic!("{}: option `{name}` is {other:?}, not a bool", self.solver),
        }
    }

    /// The value of a declared choice or name option.
    ///
    /// # Panics
    /// If `name` is not a declared choice or name option of the solver (a bug in the
    /// solver).
    pub fn choice(&self, name: &str) -> &str {
        match self.value(name) {
            OptionValue::Choice(s) => s,
            other => panic!(
                "{}: option `{name}` is {other:?}, not a choice",
                self.solver
            ),
        }
    }
}

/// `value` checked against `spec` (and parsed, if it is text).
fn check(
    solver: &'static str,
    spec: &'static OptionSpec,
    value: &OptionValue,
) -> Result<OptionValue, OptionError> {
    let wrong_type = || OptionError::Type {
        solver,
        option: spec.name,
        expected: spec.kind.expected(),
        got: value.to_string(),
    };
    let range = |min: String, max: String| OptionError::Range {
        solver,
        option: spec.name,
        min,
        max,
        got: value.to_string(),
    };
    match (spec.kind, value) {
        (OptionKind::Float { min, max, .. }, _) => {
            let x = match value {
                OptionValue::Float(x) => *x,
                OptionValue::Int(n) => *n as f64,
                OptionValue::Choice(text) => text.trim().parse().map_err(|_| wrong_type())?,
                OptionValue::Bool(_) => return Err(wrong_type()),
            };
            if !(x.is_finite() && x >= min && x <= max) {
                return Err(range(min.to_string(), max.to_string()));
            }
            Ok(OptionValue::Float(x))
        }
        (OptionKind::Int { min, max, .. }, _) => {
            let n = match value {
                OptionValue::Int(n) => *n,
                OptionValue::Choice(text) => text.trim().parse().map_err(|_| wrong_type())?,
                OptionValue::Float(_) | OptionValue::Bool(_) => return Err(wrong_type()),
            };
            if n < min || n > max {
                return Err(range(min.to_string(), max.to_string()));
            }
            Ok(OptionValue::Int(n))
        }
        (OptionKind::Bool { .. }, OptionValue::Bool(b)) => Ok(OptionValue::Bool(*b)),
        (OptionKind::Bool { .. }, OptionValue::Choice(text)) => match text.trim() {
            "true" | "yes" | "1" => Ok(OptionValue::Bool(true)),
            "false" | "no" | "0" => Ok(OptionValue::Bool(false)),
            _ => Err(wrong_type()),
        },
        (OptionKind::Bool { .. }, _) => Err(wrong_type()),
        (OptionKind::Choice { choices, .. }, OptionValue::Choice(text)) => {
            match choices.iter().find(|c| **c == text.trim()) {
                Some(c) => Ok(OptionValue::Choice(c.to_string())),
                None => Err(OptionError::Choice {
                    solver,
                    option: spec.name,
                    choices: choices.join(", "),
                    got: text.clone(),
                    help: spec.help,
                }),
            }
        }
        (OptionKind::Choice { .. }, _) => Err(wrong_type()),
        (OptionKind::Name { .. }, OptionValue::Choice(text)) => {
            Ok(OptionValue::Choice(text.trim().to_string()))
        }
        (OptionKind::Name { .. }, _) => Err(wrong_type()),
    }
}

/// The `threads` option every solver with sparse factorizations declares.
pub const THREADS: OptionSpec = OptionSpec {
    name: "threads",
    kind: OptionKind::Int {
        default: 1,
        min: 1,
        max: 256,
    },
    help: "threads of the sparse factorizations (1: sequential; 2 did not pay off on 2 cores)",
};
