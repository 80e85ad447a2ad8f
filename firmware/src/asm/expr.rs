//! Expressions: integers, symbols, `.` (the current address), parentheses,
//! unary `- ~ +`, and binary `* / % + - << >> & ^ |` (C precedence).
//! Arithmetic is 64-bit, wrapping; division by zero is an error.

use std::collections::HashMap;

use super::lexer::{Tok, Token};

/// Result of evaluating: a value, or `None` when a symbol is not yet known
/// (first pass).
pub type Value = Option<i64>;

pub struct Ctx<'a> {
    pub symbols: &'a HashMap<String, i64>,
    /// Value of `.`.
    pub here: i64,
    /// Unknown symbols are errors (second pass).
    pub final_pass: bool,
}

/// A parse or evaluation error at a token index (`None`: at the end).
pub struct ExprError {
    pub at: Option<usize>,
    pub msg: String,
}

pub struct Parser<'t> {
    pub toks: &'t [Token],
    pub pos: usize,
    /// Unary operators and parentheses open at `pos` (bounded by
    /// [`MAX_NESTING`], so no expression can overflow the stack).
    depth: u32,
}

/// Deepest nesting of parentheses and unary operators in one expression.
pub const MAX_NESTING: u32 = 256;

fn err(at: Option<usize>, msg: impl Into<String>) -> ExprError {
    ExprError {
        at,
        msg: msg.into(),
    }
}

impl<'t> Parser<'t> {
    pub fn new(toks: &'t [Token]) -> Self {
        Parser {
            toks,
            pos: 0,
            depth: 0,
        }
    }

    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos).map(|t| &t.tok)
    }

    fn here_idx(&self) -> Option<usize> {
        if self.pos < self.toks.len() {
            Some(self.pos)
        } else {
            None
        }
    }

    pub fn expr(&mut self, c: &Ctx) -> Result<Value, ExprError> {
        self.binary(c, 0)
    }

    fn binary(&mut self, c: &Ctx, min_prec: u8) -> Result<Value, ExprError> {
        let mut lhs = self.unary(c)?;
        while let Some(Tok::P(p)) = self.peek() {
            let (op, prec) = match *p {
                "|" => ("|", 1),
                "^" => ("^", 2),
                "&" => ("&", 3),
                "<<" | ">>" => (*p, 4),
                "+" | "-" => (*p, 5),
                "*" | "/" | "%" => (*p, 6),
                _ => break,
            };
            if prec < min_prec {
                break;
            }
            let at = self.here_idx();
            self.pos += 1;
            let rhs = self.binary(c, prec + 1)?;
            lhs = match (lhs, rhs) {
                (Some(a), Some(b)) => Some(match op {
                    "|" => a | b,
                    "^" => a ^ b,
                    "&" => a & b,
                    "<<" => {
                        if !(0..64).contains(&b) {
                            return Err(err(at, format!("shift by {b}")));
                        }
                        a.wrapping_shl(b as u32)
                    }
                    ">>" => {
                        if !(0..64).contains(&b) {
                            return Err(err(at, format!("shift by {b}")));
                        }
                        a.wrapping_shr(b as u32)
                    }
                    "+" => a.wrapping_add(b),
                    "-" => a.wrapping_sub(b),
                    "*" => a.wrapping_mul(b),
                    "/" | "%" => {
                        if b == 0 {
                            return Err(err(at, "division by zero"));
                        }
                        if op == "/" {
                            a.wrapping_div(b)
                        } else {
                            a.wrapping_rem(b)
                        }
                    }
                    _ => unreachable!(),
                }),
                _ => None,
            };
        }
        Ok(lhs)
    }

    fn unary(&mut self, c: &Ctx) -> Result<Value, ExprError> {
        if self.depth >= MAX_NESTING {
            return Err(err(
                self.here_idx(),
                format!("expression nested more than {MAX_NESTING} deep (parentheses and unary operators)"),
            ));
        }
        self.depth += 1;
        let v = self.unary_nested(c);
        self.depth -= 1;
        v
    }

    fn unary_nested(&mut self, c: &Ctx) -> Result<Value, ExprError> {
        match self.peek() {
            Some(Tok::P("-")) => {
                self.pos += 1;
                Ok(self.unary(c)?.map(|v| v.wrapping_neg()))
            }
            Some(Tok::P("+")) => {
                self.pos += 1;
                self.unary(c)
            }
            Some(Tok::P("~")) => {
                self.pos += 1;
                Ok(self.unary(c)?.map(|v| !v))
            }
            _ => self.primary(c),
        }
    }

    fn primary(&mut self, c: &Ctx) -> Result<Value, ExprError> {
        let at = self.here_idx();
        match self.peek().cloned() {
            Some(Tok::Int(v)) => {
                self.pos += 1;
                Ok(Some(v))
            }
            Some(Tok::P(".")) => {
                self.pos += 1;
                Ok(Some(c.here))
            }
            Some(Tok::P("(")) => {
                self.pos += 1;
                let v = self.expr(c)?;
                match self.peek() {
                    Some(Tok::P(")")) => {
                        self.pos += 1;
                        Ok(v)
                    }
                    _ => Err(err(self.here_idx(), "expected `)`")),
                }
            }
            Some(Tok::Ident(name)) => {
                self.pos += 1;
                match c.symbols.get(&name) {
                    Some(v) => Ok(Some(*v)),
                    None if c.final_pass => Err(err(at, format!("undefined symbol `{name}`"))),
                    None => Ok(None),
                }
            }
            Some(t) => Err(err(at, format!("expected a value, found {}", show(&t)))),
            None => Err(err(None, "expected a value")),
        }
    }
}

pub fn show(t: &Tok) -> String {
    match t {
        Tok::Ident(s) => format!("`{s}`"),
        Tok::Int(v) => format!("`{v}`"),
        Tok::Str(s) => format!("\"{s}\""),
        Tok::P(p) => format!("`{p}`"),
    }
}
