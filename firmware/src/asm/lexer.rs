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
    let chars: Vec<char> = line.chars().collect();
    let mut out = Vec::new();
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
            out.push(Token {
                tok: Tok::Ident(chars[s..i].iter().collect()),
                col,
            });
            continue;
        }
        if c.is_ascii_digit() {
            let s = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let text: String = chars[s..i].iter().filter(|c| **c != '_').collect();
            let lower = text.to_ascii_lowercase();
            let v = if let Some(h) = lower.strip_prefix("0x") {
                i64::from_str_radix(h, 16)
            } else if let Some(b) = lower.strip_prefix("0b") {
                i64::from_str_radix(b, 2)
            } else {
                lower.parse::<i64>()
            };
            match v {
                Ok(v) => out.push(Token {
                    tok: Tok::Int(v),
                    col,
                }),
                Err(_) => {
                    return Err(mk(
                        col,
                        format!("bad number `{}`", chars[s..i].iter().collect::<String>()),
                    ))
                }
            }
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
            let mut s = String::new();
            i += 1;
            loop {
                match chars.get(i) {
                    None => return Err(mk(col, "unterminated string".into())),
                    Some('"') => {
                        i += 1;
                        break;
                    }
                    Some('\\') => {
                        let e = match chars.get(i + 1) {
                            Some('n') => '\n',
                            Some('t') => '\t',
                            Some('0') => '\0',
                            Some('\\') => '\\',
                            Some('"') => '"',
                            _ => return Err(mk(i + 1, "unknown escape in string".into())),
                        };
                        s.push(e);
                        i += 2;
                    }
                    Some(ch) => {
                        s.push(*ch);
                        i += 1;
                    }
                }
            }
            out.push(Token {
                tok: Tok::Str(s),
                col,
            });
            continue;
        }
        let rest: String = chars[i..chars.len().min(i + 2)].iter().collect();
        match PUNCT.iter().find(|p| rest.starts_with(**p)) {
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
