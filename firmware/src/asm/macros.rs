//! Macros: `.macro NAME [P1[, P2...]]` ... `.endm` defines NAME; a line
//! `NAME a1, a2` (after any labels) is replaced by the body with `\P1`
//! replaced by `a1` and so on, `\()` by nothing (to end a parameter's name
//! inside a word: `\p\()_next`) and `\@` by the number of the expansion
//! (unique labels). A macro may be used before its definition and in
//! another macro's body, not in its own. Expansion is textual and comes before everything else; an error
//! in an expanded line names the body's line, shows it as expanded and
//! says where the macro was used.

use std::collections::HashMap;

use super::AsmError;

/// A source line after expansion: its number in the file, its text, and,
/// for a line of a macro's body, where the macro was used.
#[derive(Clone, Debug)]
pub(crate) struct Expanded {
    pub no: usize,
    pub text: String,
    pub from: Option<String>,
}

struct Macro {
    params: Vec<String>,
    /// (line number, text) of the body.
    body: Vec<(usize, String)>,
}

/// Nesting limit of macro uses (a macro that uses itself ends here).
const MAX_DEPTH: usize = 32;
/// Lines a source may expand to (macros using macros grow exponentially).
const MAX_LINES: usize = 1 << 20;

fn is_ident(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && c.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.')
}

/// The code part of a line (before a `;` or `//` comment, outside strings
/// and character literals).
fn code(line: &str) -> &str {
    let b = line.as_bytes();
    let mut quote = false;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'"' => quote = !quote,
            b'\'' if !quote && i + 2 < b.len() && b[i + 2] == b'\'' => i += 2,
            b';' if !quote => return &line[..i],
            b'/' if !quote && b.get(i + 1) == Some(&b'/') => return &line[..i],
            _ => {}
        }
        i += 1;
    }
    line
}

/// Split `s` at top-level commas (not inside parentheses or brackets).
fn split_args(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let (mut depth, mut cur) = (0i32, String::new());
    for c in s.chars() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            ',' if depth == 0 => {
                out.push(cur.trim().to_string());
                cur.clear();
                continue;
            }
            _ => {}
        }
        cur.push(c);
    }
    if !cur.trim().is_empty() || !out.is_empty() {
        out.push(cur.trim().to_string());
    }
    out
}

/// The labels at the start of a code part (`name:`), and the rest.
fn labels(code: &str) -> (Vec<&str>, &str) {
    let mut rest = code.trim_start();
    let mut out = Vec::new();
    while let Some((head, tail)) = rest.split_once(':') {
        let head = head.trim();
        if is_ident(head) && !head.starts_with('.') {
            out.push(head);
            rest = tail.trim_start();
        } else {
            break;
        }
    }
    (out, rest)
}

/// Words that cannot name a macro: instructions and directives.
/// The column (1-based, in characters) of `word` in `line`, or 1.
fn col_of(line: &str, word: &str) -> usize {
    line.find(word).map_or(1, |p| line[..p].chars().count() + 1)
}

fn reserved(name: &str, is_mnemonic: &dyn Fn(&str) -> bool) -> bool {
    name.starts_with('.') || is_mnemonic(name)
}

/// Expand the macros of `src` (`file` names it in errors; `is_mnemonic`
/// says which words are instructions).
pub(crate) fn expand(
    src: &str,
    file: &str,
    is_mnemonic: &dyn Fn(&str) -> bool,
) -> Result<Vec<Expanded>, AsmError> {
    let lines: Vec<&str> = src.lines().collect();
    let err = |no: usize, text: &str, col: usize, msg: String| AsmError {
        file: file.to_string(),
        line: no,
        col,
        message: msg,
        text: text.to_string(),
    };
    let mut macros: HashMap<String, Macro> = HashMap::new();
    let mut out = Vec::with_capacity(lines.len());
    let mut uses = 0usize;
    let mut k = 0;
    while k < lines.len() {
        let line = lines[k];
        let no = k + 1;
        let c = code(line).trim();
        let first = c.split_whitespace().next().unwrap_or("");
        if first == ".endm" {
            return Err(err(
                no,
                line,
                col_of(line, ".endm"),
                "`.endm` without `.macro`".into(),
            ));
        }
        if first != ".macro" {
            out.push(Expanded {
                no,
                text: line.to_string(),
                from: None,
            });
            k += 1;
            continue;
        }
        // A definition.
        let (name, m, end) = definition(&lines, k, &macros, is_mnemonic, &err)?;
        macros.insert(name, m);
        k = end;
    }
    // Uses, depth first.
    let mut result = Vec::with_capacity(out.len());
    for l in out {
        expand_line(l, &macros, &mut result, &mut uses, 0, file)?;
    }
    Ok(result)
}

/// The macro defined from line `k` (its `.macro` line): its name, the
/// macro, and the line after its `.endm`.
fn definition(
    lines: &[&str],
    k: usize,
    macros: &HashMap<String, Macro>,
    is_mnemonic: &dyn Fn(&str) -> bool,
    err: &dyn Fn(usize, &str, usize, String) -> AsmError,
) -> Result<(String, Macro, usize), AsmError> {
    let line = lines[k];
    let no = k + 1;
    let c = code(line).trim();
    let rest = c[".macro".len()..].trim();
    let (name, params) = match rest.split_once(char::is_whitespace) {
        Some((n, p)) => (n.trim(), p.trim()),
        None => (rest, ""),
    };
    if !is_ident(name) {
        return Err(err(
            no,
            line,
            col_of(line, ".macro") + 7,
            "`.macro NAME [PARAM, ...]` needs a name".into(),
        ));
    }
    if reserved(name, is_mnemonic) {
        return Err(err(
            no,
            line,
            col_of(line, name),
            format!("`{name}` is an instruction or a directive: not a macro name"),
        ));
    }
    if macros.contains_key(name) {
        return Err(err(
            no,
            line,
            col_of(line, name),
            format!("macro `{name}` is defined twice"),
        ));
    }
    let params: Vec<String> = if params.is_empty() {
        Vec::new()
    } else {
        split_args(params)
    };
    for p in &params {
        if !is_ident(p) || p.contains('.') {
            return Err(err(
                no,
                line,
                col_of(line, p),
                format!("macro parameter `{p}`: a parameter is a name"),
            ));
        }
    }
    let mut body = Vec::new();
    let mut j = k + 1;
    loop {
        let Some(l) = lines.get(j) else {
            return Err(err(
                no,
                line,
                col_of(line, ".macro"),
                format!("`.macro {name}` without `.endm`"),
            ));
        };
        let w = code(l).split_whitespace().next().unwrap_or("");
        if w == ".endm" {
            break;
        }
        if w == ".macro" {
            return Err(err(
                j + 1,
                l,
                col_of(l, ".macro"),
                format!("`.macro` inside `.macro {name}` (end it with `.endm` first)"),
            ));
        }
        body.push((j + 1, l.to_string()));
        j += 1;
    }
    Ok((name.to_string(), Macro { params, body }, j + 1))
}

fn expand_line(
    l: Expanded,
    macros: &HashMap<String, Macro>,
    out: &mut Vec<Expanded>,
    uses: &mut usize,
    depth: usize,
    file: &str,
) -> Result<(), AsmError> {
    let c = code(&l.text);
    let (labels, rest) = labels(c);
    let name = rest.split_whitespace().next().unwrap_or("");
    let Some(m) = macros.get(name) else {
        out.push(l);
        return Ok(());
    };
    if out.len() >= MAX_LINES {
        return Err(AsmError {
            file: file.to_string(),
            line: l.no,
            col: 1,
            message: format!(
                "the macros expand to over {MAX_LINES} lines{}",
                l.from.as_deref().unwrap_or("")
            ),
            text: l.text.clone(),
        });
    }
    let err = |col: usize, msg: String| AsmError {
        file: file.to_string(),
        line: l.no,
        col,
        message: format!("{msg}{}", l.from.as_deref().unwrap_or("")),
        text: l.text.clone(),
    };
    let col = l
        .text
        .find(name)
        .map_or(1, |p| l.text[..p].chars().count() + 1);
    if depth >= MAX_DEPTH {
        return Err(err(
            col,
            format!("macros used more than {MAX_DEPTH} deep (does `{name}` use itself?)"),
        ));
    }
    let args_text = rest[name.len()..].trim();
    let args = if args_text.is_empty() {
        Vec::new()
    } else {
        split_args(args_text)
    };
    if args.len() != m.params.len() {
        return Err(err(
            col,
            format!(
                "macro `{name}` takes {} argument(s) ({}), found {}",
                m.params.len(),
                m.params.join(", "),
                args.len()
            ),
        ));
    }
    for lb in labels {
        out.push(Expanded {
            no: l.no,
            text: format!("{lb}:"),
            from: l.from.clone(),
        });
    }
    *uses += 1;
    let this = *uses;
    let from = format!(
        " (in macro `{name}`, used at line {}){}",
        l.no,
        l.from.as_deref().unwrap_or("")
    );
    // Longest parameter names first, so `\pa` is not taken for `\p` + `a`.
    let mut order: Vec<usize> = (0..m.params.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(m.params[i].len()));
    for (bno, text) in &m.body {
        let use_ = Use {
            name,
            m,
            args: &args,
            order: &order,
            this,
            from: &from,
            file,
        };
        let s = use_.substitute(*bno, text)?;
        let e = Expanded {
            no: *bno,
            text: s,
            from: Some(from.clone()),
        };
        expand_line(e, macros, out, uses, depth + 1, file)?;
    }
    Ok(())
}

/// One use of a macro, its body's lines being written out.
struct Use<'a> {
    name: &'a str,
    m: &'a Macro,
    args: &'a [String],
    /// The parameters, longest names first (so `\pa` is not taken for
    /// `\p` + `a`).
    order: &'a [usize],
    /// The use's number (`\@`).
    this: usize,
    /// Where it was used, for errors.
    from: &'a str,
    file: &'a str,
}

impl Use<'_> {
    /// Body line `text` (line `bno`) with its parameters, `\@` and `\()`
    /// replaced.
    fn substitute(&self, bno: usize, text: &str) -> Result<String, AsmError> {
        let (m, name, from) = (self.m, self.name, self.from);
        let mut s = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(p) = rest.find('\\') {
            s.push_str(&rest[..p]);
            let after = &rest[p + 1..];
            if let Some(t) = after.strip_prefix("()") {
                rest = t;
            } else if let Some(t) = after.strip_prefix('@') {
                s.push_str(&self.this.to_string());
                rest = t;
            } else if let Some(&i) = self
                .order
                .iter()
                .find(|&&i| after.starts_with(m.params[i].as_str()))
            {
                s.push_str(&self.args[i]);
                rest = &after[m.params[i].len()..];
            } else {
                let word: String = after
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                return Err(AsmError {
                    file: self.file.to_string(),
                    line: bno,
                    col: text[..text.len() - rest.len() + p].chars().count() + 1,
                    message: format!(
                        "`\\{word}` is not a parameter of macro `{name}` ({}){from}",
                        m.params.join(", ")
                    ),
                    text: text.to_string(),
                });
            }
        }
        s.push_str(rest);
        Ok(s)
    }
}
