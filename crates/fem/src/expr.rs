//! Beltrami coefficients given as expressions of `z`, e.g. `0.6*z`, `0.6*z^3`,
//! `0.3+0.3i`, `conj(z)*z/4`, `0.5*exp(i*z)`.
//!
//! # Grammar
//!
//! ```text
//! expr    = term { ("+" | "-") term }
//! term    = unary { ("*" | "/") unary }
//! unary   = ("-" | "+") unary | power
//! power   = primary [ "^" unary ]          exponent: a constant integer (may be negative)
//! primary = number | "i" | "z" | name "(" expr ")" | "(" expr ")"
//! number  = digits [ "." digits ] [ ("e" | "E") [sign] digits ] [ "i" ]
//! name    = "conj" | "abs" | "exp"
//! ```
//!
//! So `-z^2 = -(z^2)`, `2*z^3 = 2 (z^3)`, `2^3^2 = 2^9`, `z^-2 = 1 / z^2`, `2i` is the
//! number `2 i`, and there is no implicit multiplication (`2z` is an error). Values are
//! complex: `abs(w) = |w|` (real), `conj(w) = re w - i im w`, `exp(w) = e^w`.
//! Whitespace is ignored. Errors ([`ExprError`]) give the 1-based column (in
//! characters) of the problem.
//!
//! # Depth
//!
//! Parsing and evaluation recurse once per level of nesting, so an expression may nest
//! at most [`MAX_DEPTH`] levels deep. A level is opened by each `(` (of a parenthesis or
//! a function call), each sign and each `^`; a chain `a + b - c` or `a * b / c` is one
//! node with a list of terms ([`Expr::Sum`], [`Expr::Product`]), evaluated in a loop, so
//! a sum of a thousand terms is as deep as one.
//! Deeper input, such as ten thousand `(`, gets [`ExprError::TooDeep`] with the column
//! of the token that opens level `MAX_DEPTH + 1`, instead of a stack overflow.

use beltrami_mesh::Mesh;
use num_complex::Complex64;
use thiserror::Error;

use crate::element::check_planar;
use crate::{BeltramiField, FemError, Frame};

/// The deepest nesting [`Expr::parse`] accepts (module docs, "Depth").
pub const MAX_DEPTH: usize = 64;

/// Why an expression could not be parsed. Columns are 1-based, in characters.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ExprError {
    /// The expression is empty (or only whitespace).
    #[error("the expression is empty")]
    Empty,
    /// A character that starts no token.
    #[error("column {column}: unexpected character `{character}`")]
    UnexpectedCharacter {
        /// Where.
        column: usize,
        /// The character.
        character: char,
    },
    /// A token (or the end) where something else was expected.
    #[error("column {column}: expected {expected}, found {found}")]
    UnexpectedToken {
        /// Where (one past the last character for the end of the expression).
        column: usize,
        /// What was expected.
        expected: &'static str,
        /// What was found (`end of expression` at the end).
        found: String,
    },
    /// A `(` never closed (column of the `(`), or a `)` never opened.
    #[error("column {column}: unbalanced parenthesis")]
    UnbalancedParenthesis {
        /// The unmatched parenthesis.
        column: usize,
    },
    /// An exponent that is not a constant integer (`z^0.5`, `z^z`).
    #[error("column {column}: the power must be a constant integer, found {found}")]
    NonIntegerPower {
        /// Where the exponent starts.
        column: usize,
        /// The exponent found (its value, or `an expression of z`).
        found: String,
    },
    /// A name followed by `(` that is not a known function.
    #[error("column {column}: unknown function `{name}` (known: conj, abs, exp)")]
    UnknownFunction {
        /// Where the name starts.
        column: usize,
        /// The name.
        name: String,
    },
    /// A name that is neither `z` nor `i` nor a function call.
    #[error("column {column}: unknown name `{name}` (the variable is `z`, the imaginary unit `i`)")]
    UnknownName {
        /// Where the name starts.
        column: usize,
        /// The name.
        name: String,
    },
    /// An expression nested more than [`MAX_DEPTH`] levels deep (module docs, "Depth").
    #[error("column {column}: the expression nests more than {max} levels deep", max = MAX_DEPTH)]
    TooDeep {
        /// The `(`, sign, `^` or operator that opens level `MAX_DEPTH + 1`.
        column: usize,
    },
}

/// A function of one complex argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Function {
    Conj,
    Abs,
    Exp,
}

/// The operator before a later term of a [`Expr::Sum`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AddOp {
    /// `+`.
    Add,
    /// `-`.
    Sub,
}

/// The operator before a later factor of a [`Expr::Product`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MulOp {
    /// `*`.
    Mul,
    /// `/`.
    Div,
}

/// A parsed expression of `z` (module docs); evaluate it with [`Expr::eval`].
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A complex constant.
    Number(Complex64),
    /// The variable `z`.
    Z,
    /// `-a`.
    Neg(Box<Expr>),
    /// `a_0 + a_1 - a_2 ...`: a chain of sums and differences evaluated left to right,
    /// each later term with its operator.
    Sum(Box<Expr>, Vec<(AddOp, Expr)>),
    /// `a_0 * a_1 / a_2 ...`: a chain of products and quotients evaluated left to right.
    Product(Box<Expr>, Vec<(MulOp, Expr)>),
    /// `a ^ n`, `n` an integer.
    Pow(Box<Expr>, i32),
    /// `conj(a)`.
    Conj(Box<Expr>),
    /// `abs(a)`.
    Abs(Box<Expr>),
    /// `exp(a)`.
    Exp(Box<Expr>),
}

impl Expr {
    /// Parses `text` (module docs).
    pub fn parse(text: &str) -> Result<Self, ExprError> {
        let tokens = tokenize(text)?;
        if tokens.len() == 1 {
            return Err(ExprError::Empty);
        }
        let mut parser = Parser { tokens, next: 0 };
        let expr = parser.expr(0)?;
        let token = parser.peek();
        match token.kind {
            Kind::End => Ok(expr),
            Kind::Close => Err(ExprError::UnbalancedParenthesis {
                column: token.column,
            }),
            _ => Err(parser.unexpected("an operator or the end of the expression")),
        }
    }

    /// The value at `z`. Division by zero and negative powers of zero give infinities
    /// or NaN, as in floating point.
    pub fn eval(&self, z: Complex64) -> Complex64 {
        match self {
            Expr::Number(c) => *c,
            Expr::Z => z,
            Expr::Neg(a) => -a.eval(z),
            Expr::Sum(first, rest) => rest.iter().fold(first.eval(z), |acc, (op, t)| match op {
                AddOp::Add => acc + t.eval(z),
                AddOp::Sub => acc - t.eval(z),
            }),
            Expr::Product(first, rest) => {
                rest.iter().fold(first.eval(z), |acc, (op, t)| match op {
                    MulOp::Mul => acc * t.eval(z),
                    MulOp::Div => acc / t.eval(z),
                })
            }
            Expr::Pow(a, n) => a.eval(z).powi(*n),
            Expr::Conj(a) => a.eval(z).conj(),
            Expr::Abs(a) => Complex64::new(a.eval(z).norm(), 0.0),
            Expr::Exp(a) => a.eval(z).exp(),
        }
    }

    /// True if the expression does not involve `z`.
    fn is_constant(&self) -> bool {
        match self {
            Expr::Number(_) => true,
            Expr::Z => false,
            Expr::Neg(a) | Expr::Pow(a, _) | Expr::Conj(a) | Expr::Abs(a) | Expr::Exp(a) => {
                a.is_constant()
            }
            Expr::Sum(first, rest) => {
                first.is_constant() && rest.iter().all(|(_, t)| t.is_constant())
            }
            Expr::Product(first, rest) => {
                first.is_constant() && rest.iter().all(|(_, t)| t.is_constant())
            }
        }
    }

    /// The field `mu_f = expr(z_f)` in [`Frame::Global`], `z_f = x + i y` the centroid
    /// of face `f` of a mesh in the plane z = 0 (the mean of its vertices).
    ///
    /// Fails with [`FemError::NotPlanar`] for a mesh off the plane. The values are not
    /// checked; [`BeltramiField::check`] names a face with `|mu| >= 1` or a non-finite
    /// value.
    pub fn field(&self, mesh: &Mesh) -> Result<BeltramiField, FemError> {
        check_planar(mesh)?;
        let mu = mesh
            .faces()
            .map(|f| {
                let c = mesh.face_centroid(f);
                self.eval(Complex64::new(c.x, c.y))
            })
            .collect();
        Ok(BeltramiField::new(Frame::Global, mu))
    }
}

impl std::str::FromStr for Expr {
    type Err = ExprError;

    fn from_str(text: &str) -> Result<Self, ExprError> {
        Self::parse(text)
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Kind {
    Number(Complex64),
    Name(String),
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    Open,
    Close,
    End,
}

#[derive(Debug, Clone, PartialEq)]
struct Token {
    kind: Kind,
    /// 1-based column of the first character.
    column: usize,
}

impl Token {
    fn describe(&self) -> String {
        match &self.kind {
            Kind::Number(c) if c.im == 0.0 => format!("`{}`", c.re),
            Kind::Number(c) => format!("`{}i`", c.im),
            Kind::Name(n) => format!("`{n}`"),
            Kind::Plus => "`+`".into(),
            Kind::Minus => "`-`".into(),
            Kind::Star => "`*`".into(),
            Kind::Slash => "`/`".into(),
            Kind::Caret => "`^`".into(),
            Kind::Open => "`(`".into(),
            Kind::Close => "`)`".into(),
            Kind::End => "end of expression".into(),
        }
    }
}

/// Splits `text` into tokens, ending with [`Kind::End`].
fn tokenize(text: &str) -> Result<Vec<Token>, ExprError> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut k = 0;
    while k < chars.len() {
        let c = chars[k];
        let column = k + 1;
        let simple = match c {
            '+' => Some(Kind::Plus),
            '-' => Some(Kind::Minus),
            '*' => Some(Kind::Star),
            '/' => Some(Kind::Slash),
            '^' => Some(Kind::Caret),
            '(' => Some(Kind::Open),
            ')' => Some(Kind::Close),
            _ => None,
        };
        if let Some(kind) = simple {
            tokens.push(Token { kind, column });
            k += 1;
        } else if c.is_whitespace() {
            k += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let start = k;
            while k < chars.len() && (chars[k].is_ascii_digit() || chars[k] == '.') {
                k += 1;
            }
            // An exponent: e or E followed by digits, with an optional sign.
            if k < chars.len() && (chars[k] == 'e' || chars[k] == 'E') {
                let mut j = k + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    k = j;
                    while k < chars.len() && chars[k].is_ascii_digit() {
                        k += 1;
                    }
                }
            }
            let literal: String = chars[start..k].iter().collect();
            let value: f64 = literal
                .parse()
                .map_err(|_| ExprError::UnexpectedCharacter {
                    column,
                    character: c,
                })?;
            let imaginary = k < chars.len()
                && chars[k] == 'i'
                && !chars
                    .get(k + 1)
                    .is_some_and(|&n| n.is_alphanumeric() || n == '_');
            let kind = if imaginary {
                k += 1;
                Kind::Number(Complex64::new(0.0, value))
            } else {
                Kind::Number(Complex64::new(value, 0.0))
            };
            tokens.push(Token { kind, column });
        } else if c.is_alphabetic() || c == '_' {
            let start = k;
            while k < chars.len() && (chars[k].is_alphanumeric() || chars[k] == '_') {
                k += 1;
            }
            let name = chars[start..k].iter().collect();
            tokens.push(Token {
                kind: Kind::Name(name),
                column,
            });
        } else {
            return Err(ExprError::UnexpectedCharacter {
                column,
                character: c,
            });
        }
    }
    tokens.push(Token {
        kind: Kind::End,
        column: chars.len() + 1,
    });
    Ok(tokens)
}

/// The depth of a level opened at `column` inside a level of depth `depth`:
/// `depth + 1`, or [`ExprError::TooDeep`] beyond [`MAX_DEPTH`].
fn deeper(depth: usize, column: usize) -> Result<usize, ExprError> {
    if depth < MAX_DEPTH {
        Ok(depth + 1)
    } else {
        Err(ExprError::TooDeep { column })
    }
}

/// Recursive descent over the tokens (module docs). Each rule takes the depth of the
/// level it parses (module docs, "Depth") and passes [`deeper`] levels down.
struct Parser {
    tokens: Vec<Token>,
    next: usize,
}

impl Parser {
    fn peek(&self) -> &Token {
        // The last token is End, which is never consumed.
        &self.tokens[self.next.min(self.tokens.len() - 1)]
    }

    fn bump(&mut self) -> Token {
        let token = self.peek().clone();
        if token.kind != Kind::End {
            self.next += 1;
        }
        token
    }

    fn unexpected(&self, expected: &'static str) -> ExprError {
        let token = self.peek();
        ExprError::UnexpectedToken {
            column: token.column,
            expected,
            found: token.describe(),
        }
    }

    fn expr(&mut self, depth: usize) -> Result<Expr, ExprError> {
        let first = self.term(depth)?;
        let mut rest = Vec::new();
        loop {
            let op = match self.peek().kind {
                Kind::Plus => AddOp::Add,
                Kind::Minus => AddOp::Sub,
                _ => break,
            };
            self.bump();
            rest.push((op, self.term(depth)?));
        }
        Ok(if rest.is_empty() {
            first
        } else {
            Expr::Sum(Box::new(first), rest)
        })
    }

    fn term(&mut self, depth: usize) -> Result<Expr, ExprError> {
        let first = self.unary(depth)?;
        let mut rest = Vec::new();
        loop {
            let op = match self.peek().kind {
                Kind::Star => MulOp::Mul,
                Kind::Slash => MulOp::Div,
                _ => break,
            };
            self.bump();
            rest.push((op, self.unary(depth)?));
        }
        Ok(if rest.is_empty() {
            first
        } else {
            Expr::Product(Box::new(first), rest)
        })
    }

    fn unary(&mut self, depth: usize) -> Result<Expr, ExprError> {
        let token = self.peek();
        let column = token.column;
        match token.kind {
            Kind::Minus => {
                self.bump();
                Ok(Expr::Neg(Box::new(self.unary(deeper(depth, column)?)?)))
            }
            Kind::Plus => {
                self.bump();
                self.unary(deeper(depth, column)?)
            }
            _ => self.power(depth),
        }
    }

    fn power(&mut self, depth: usize) -> Result<Expr, ExprError> {
        let base = self.primary(depth)?;
        if self.peek().kind != Kind::Caret {
            return Ok(base);
        }
        let caret = self.bump().column;
        let column = self.peek().column;
        let exponent = self.unary(deeper(depth, caret)?)?;
        let non_integer = |found: String| ExprError::NonIntegerPower { column, found };
        if !exponent.is_constant() {
            return Err(non_integer("an expression of z".into()));
        }
        let n = exponent.eval(Complex64::new(0.0, 0.0));
        let integral = n.im == 0.0 && n.re.fract() == 0.0 && n.re.abs() <= f64::from(i32::MAX);
        if !integral {
            return Err(non_integer(if n.im == 0.0 {
                n.re.to_string()
            } else {
                n.to_string()
            }));
        }
        Ok(Expr::Pow(Box::new(base), n.re as i32))
    }

    fn primary(&mut self, depth: usize) -> Result<Expr, ExprError> {
        let token = self.peek().clone();
        match token.kind {
            Kind::Number(c) => {
                self.bump();
                Ok(Expr::Number(c))
            }
            Kind::Open => {
                self.bump();
                let inner = self.expr(deeper(depth, token.column)?)?;
                self.close(token.column)?;
                Ok(inner)
            }
            Kind::Name(name) => {
                self.bump();
                if self.peek().kind == Kind::Open {
                    let function = match name.as_str() {
                        "conj" => Function::Conj,
                        "abs" => Function::Abs,
                        "exp" => Function::Exp,
                        _ => {
                            return Err(ExprError::UnknownFunction {
                                column: token.column,
                                name,
                            });
                        }
                    };
                    let open = self.bump().column;
                    let argument = Box::new(self.expr(deeper(depth, open)?)?);
                    self.close(open)?;
                    return Ok(match function {
                        Function::Conj => Expr::Conj(argument),
                        Function::Abs => Expr::Abs(argument),
                        Function::Exp => Expr::Exp(argument),
                    });
                }
                match name.as_str() {
                    "z" => Ok(Expr::Z),
                    "i" => Ok(Expr::Number(Complex64::new(0.0, 1.0))),
                    _ => Err(ExprError::UnknownName {
                        column: token.column,
                        name,
                    }),
                }
            }
            Kind::Close => Err(ExprError::UnbalancedParenthesis {
                column: token.column,
            }),
            _ => Err(self.unexpected("a number, `z`, `i`, a function or `(`")),
        }
    }

    /// Consumes the `)` closing the `(` at column `open`.
    fn close(&mut self, open: usize) -> Result<(), ExprError> {
        match self.peek().kind {
            Kind::Close => {
                self.bump();
                Ok(())
            }
            Kind::End => Err(ExprError::UnbalancedParenthesis { column: open }),
            _ => Err(self.unexpected("`)` or an operator")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    fn value(text: &str, z: Complex64) -> Complex64 {
        Expr::parse(text).unwrap().eval(z)
    }

    fn close(a: Complex64, b: Complex64) -> bool {
        (a - b).norm() <= 1e-14 * (1.0 + b.norm())
    }

    #[test]
    fn numbers() {
        let z = c(0.0, 0.0);
        assert_eq!(value("0.6", z), c(0.6, 0.0));
        assert_eq!(value("i", z), c(0.0, 1.0));
        assert_eq!(value("2i", z), c(0.0, 2.0));
        assert_eq!(value("0.3+0.3i", z), c(0.3, 0.3));
        assert_eq!(value(" 1e-1 ", z), c(0.1, 0.0));
        assert_eq!(value("2.5E+1i", z), c(0.0, 25.0));
        assert_eq!(value(".5", z), c(0.5, 0.0));
    }

    #[test]
    fn precedence() {
        let z = c(0.3, -0.7);
        assert!(close(value("-z^2", z), -(z * z)));
        assert!(close(value("2*z^3", z), 2.0 * z * z * z));
        assert!(close(value("0.6*z", z), 0.6 * z));
        assert!(close(value("conj(z)*z", z), c(z.norm_sqr(), 0.0)));
        assert!(close(value("exp(i*z)", z), (c(0.0, 1.0) * z).exp()));
        assert!(close(value("1 + 2 * 3", z), c(7.0, 0.0)));
        assert!(close(value("(1 + 2) * 3", z), c(9.0, 0.0)));
        assert!(close(value("8 / 2 / 2", z), c(2.0, 0.0)));
        assert!(close(value("1 - 2 - 3", z), c(-4.0, 0.0)));
        assert!(close(value("2^3^2", z), c(512.0, 0.0)));
        assert!(close(value("z^-2", z), 1.0 / (z * z)));
        assert!(close(value("z^(1-3)", z), 1.0 / (z * z)));
        assert!(close(value("2*-z", z), -2.0 * z));
        assert!(close(value("abs(z)", z), c(z.norm(), 0.0)));
        assert!(close(value("abs(-3)/4", z), c(0.75, 0.0)));
        assert!(close(value("z^0", z), c(1.0, 0.0)));
    }

    #[test]
    fn errors_give_the_column() {
        let err = |text: &str| Expr::parse(text).unwrap_err();
        assert_eq!(
            err("0.6*z$"),
            ExprError::UnexpectedCharacter {
                column: 6,
                character: '$'
            }
        );
        assert_eq!(err("(z+1"), ExprError::UnbalancedParenthesis { column: 1 });
        assert_eq!(err("z+1)"), ExprError::UnbalancedParenthesis { column: 4 });
        assert_eq!(err("exp(z"), ExprError::UnbalancedParenthesis { column: 4 });
        assert_eq!(
            err("z^0.5"),
            ExprError::NonIntegerPower {
                column: 3,
                found: "0.5".into()
            }
        );
        assert!(matches!(
            err("z^z"),
            ExprError::NonIntegerPower { column: 3, .. }
        ));
        assert_eq!(
            err("0.5*sin(z)"),
            ExprError::UnknownFunction {
                column: 5,
                name: "sin".into()
            }
        );
        assert_eq!(
            err("w"),
            ExprError::UnknownName {
                column: 1,
                name: "w".into()
            }
        );
        assert!(matches!(
            err("2z"),
            ExprError::UnexpectedToken { column: 2, .. }
        ));
        assert!(matches!(
            err("z +"),
            ExprError::UnexpectedToken { column: 4, .. }
        ));
        assert_eq!(err("  "), ExprError::Empty);
        // The message names the column.
        assert!(err("z^0.5").to_string().contains("column 3"));
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        let err = |text: &str| Expr::parse(text).unwrap_err();
        let n = 100_000;
        let too_deep = ExprError::TooDeep {
            column: MAX_DEPTH + 1,
        };
        assert_eq!(
            err(&("(".repeat(n) + "z" + &")".repeat(n))),
            too_deep.clone()
        );
        assert_eq!(err(&("-".repeat(n) + "z")), too_deep.clone());
        assert_eq!(err(&("+".repeat(n) + "z")), too_deep);
        // Function calls: the level opens at the `(` of the 65th `exp(`.
        assert_eq!(
            err(&("exp(".repeat(n) + "z" + &")".repeat(n))),
            ExprError::TooDeep {
                column: 4 * (MAX_DEPTH + 1)
            }
        );
        // Powers: at the 65th `^`.
        assert_eq!(
            err(&("2^".repeat(n) + "1")),
            ExprError::TooDeep {
                column: 2 * (MAX_DEPTH + 1),
            }
        );
        // Chains are flat: a sum or product of 100,001 terms parses and evaluates.
        let z = c(0.3, -0.7);
        assert_eq!(value(&("1+".repeat(n) + "z"), z), n as f64 + z);
        assert!(close(value(&("1*".repeat(n) + "z/1"), z), z));
        assert!(
            err(&"(".repeat(n))
                .to_string()
                .contains(&format!("column {}", MAX_DEPTH + 1))
        );
    }

    #[test]
    fn nesting_at_the_limit_parses() {
        let z = c(0.3, -0.7);
        let d = MAX_DEPTH;
        assert_eq!(value(&("(".repeat(d) + "z" + &")".repeat(d)), z), z);
        assert_eq!(value(&("-".repeat(d) + "z"), z), z);
        assert_eq!(value(&("conj(".repeat(d) + "z" + &")".repeat(d)), z), z);
        assert!(close(
            value(&("z+".repeat(d) + "z"), z),
            (d as f64 + 1.0) * z
        ));
        assert!(close(value(&("1^".repeat(d) + "1"), z), c(1.0, 0.0)));
        assert!(Expr::parse(&("(".repeat(d + 1) + "z" + &")".repeat(d + 1))).is_err());
    }
}
