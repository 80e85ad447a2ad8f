//! Tokens of one source line, with their columns.

use super::AsmError;

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// Identifier, mnemonic or directive (may contain `.` after the first
    /// character: `cmp.lt`, `.org`).
    Ident(String),
    Int(i64),
    Str(String),
    /// Punctuation: `, : ( ) [ ] + - * / % << >> & | ^ ~ # ! = .`
    P(&'static str),
}

#[derive(Clone, Debug)]
pub struct Token {
    pub tok: Tok,
    /// 1-based column (in characters).
    pub col: usize,
}

const PUNCT: &[&str] = &[
    "<<", ">>", ",", ":", "(", ")", "[", "]", "+", "-", "*", "/", "%", "&", "|", "^", "~", "#",
    "!", "=", ".",
];

/// Split a line into tokens; comments (`;` or `//` to the end of the line)
/// are dropped.
pub fn lex(line: &str, mk: &dyn Fn(usize, String) -> AsmError) -> Result<Vec<Token>, AsmError> {
    // (One allocation: a line has at most as many characters as bytes.)
    let mut chars: Vec<char> = Vec::with_capacity(line.len());
    chars.extend(line.chars());
    let mut out = Vec::with_capacity(8);
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let col = i + 1;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if c == ';' || (c == '/' && chars.get(i + 1) == Some(&'/')) {
            break;
        }
        if c.is_ascii_alphabetic()
            || c == '_'
            || (c == '.'
                && chars
                    .get(i + 1)
                    .is_some_and(|n| n.is_ascii_alphabetic() || *n == '_'))
        {
            let s = i;
            i += 1;
            while i < chars.len()
                && (chars[i].is_ascii_alphanumeric() || chars[i] == '_' || chars[i] == '.')
            {
                i += 1;
            }
            let mut id = String::with_capacity(i - s);
            id.extend(&chars[s..i]);
            out.push(Token {
                tok: Tok::Ident(id),
                col,
            });
            continue;
        }
        if c.is_ascii_digit() {
            let (v, end) = number(&chars, i, mk)?;
            out.push(Token {
                tok: Tok::Int(v),
                col,
            });
            i = end;
            continue;
        }
        if c == '\'' {
            // character literal 'a'
            if i + 2 < chars.len() && chars[i + 2] == '\'' {
                out.push(Token {
                    tok: Tok::Int(chars[i + 1] as i64),
                    col,
                });
                i += 3;
                continue;
            }
            return Err(mk(col, "bad character literal (write 'a')".into()));
        }
        if c == '"' {
            let (s, end) = string(&chars, i, mk)?;
            out.push(Token {
                tok: Tok::Str(s),
                col,
            });
            i = end;
            continue;
        }
        let next = chars.get(i + 1).copied();
        let punct = PUNCT.iter().find(|p| {
            let mut pc = p.chars();
            pc.next() == Some(c) && pc.next().is_none_or(|second| Some(second) == next)
        });
        match punct {
            Some(p) => {
                out.push(Token {
                    tok: Tok::P(p),
                    col,
                });
                i += p.chars().count();
            }
            None if c.is_control() => {
                return Err(mk(
                    col,
                    format!("unexpected control character U+{:04X}", c as u32),
                ))
            }
            None => return Err(mk(col, format!("unexpected character `{c}`"))),
        }
    }
    Ok(out)
}

/// The number at `chars[s]` (a digit) and where it ends: `_` separates
/// digit groups anywhere; then `0x` or `0b` (any case) and at least one
/// digit of the radix.
fn number(
    chars: &[char],
    s: usize,
    mk: &dyn Fn(usize, String) -> AsmError,
) -> Result<(i64, usize), AsmError> {
    let mut i = s;
    while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
        i += 1;
    }
    let digits: Vec<char> = chars[s..i].iter().filter(|c| **c != '_').copied().collect();
    let (radix, body) = match digits.as_slice() {
        ['0', 'x' | 'X', rest @ ..] => (16, rest),
        ['0', 'b' | 'B', rest @ ..] => (2, rest),
        d => (10, d),
    };
    let mut v: Result<i64, ()> = if body.is_empty() { Err(()) } else { Ok(0) };
    for ch in body {
        v = v.and_then(|acc| {
            let d = ch.to_digit(radix).ok_or(())?;
            acc.checked_mul(radix as i64)
                .and_then(|x| x.checked_add(d as i64))
                .ok_or(())
        });
    }
    match v {
        Ok(v) => Ok((v, i)),
        Err(_) => Err(mk(
            s + 1,
            format!("bad number `{}`", chars[s..i].iter().collect::<String>()),
        )),
    }
}

/// The string literal at `chars[s]` (its opening `"`), its escapes
/// resolved, and where it ends.
fn string(
    chars: &[char],
    s: usize,
    mk: &dyn Fn(usize, String) -> AsmError,
) -> Result<(String, usize), AsmError> {
    let mut out = String::new();
    let mut i = s + 1;
    loop {
        match chars.get(i) {
            None => return Err(mk(s + 1, "unterminated string".into())),
            Some('"') => return Ok((out, i + 1)),
            Some('\\') => {
                let e = match chars.get(i + 1) {
                    Some('n') => '\n',
                    Some('t') => '\t',
                    Some('0') => '\0',
                    Some('\\') => '\\',
                    Some('"') => '"',
                    _ => return Err(mk(i + 1, "unknown escape in string".into())),
                };
                out.push(e);
                i += 2;
            }
            Some(ch) => {
                out.push(*ch);
                i += 1;
            }
        }
    }
}
