//! Expressions with ca65's operators and precedence (not C's):
//!
//! | level | operators |
//! |---|---|
//! | 1 (tightest) | unary `+ - ~ < > ^ !`, `.bitnot`, pseudo-functions |
//! | 2 | `* / .mod & ^ << >>` `.bitand .bitxor .shl .shr` |
//! | 3 | `+ - \|` `.bitor` |
//! | 4 | `= <> < > <= >=` |
//! | 5 | `&& .and .xor` |
//! | 6 | `\|\| .or` |
//! | 7 (loosest) | `! .not` |
//!
//! So `a+b&c` is `a+(b&c)` and `!a=b` is `!(a=b)`. Nodes go into the
//! program's arena; names resolve to symbols as they are read, in the
//! current scope.

use isa::objfmt::{BinaryOp, UnaryOp};

use crate::asm::{Asm, Frame, PResult, Reported};
use crate::cursor::Cursor;
use crate::diag::{self, Span};
use crate::expr::{EvalErr, Value};
use crate::intern::{Dir, Keyword};
use crate::lexer::{Tok, Token};
use crate::model::{GLOBAL_SCOPE, Node, NodeId, ScopeId, SymDef, SymId};

const MAX_NESTING: u32 = 256;

/// `.version`: ca65 2.18, as Debian's ca65 2.19 package reports itself.
const CA65_VERSION: i64 = 2 * 0x100 + 18 * 0x10;

impl Asm<'_> {
    fn directive_of(&self, tok: &Token) -> Option<Dir> {
        if tok.kind != Tok::Directive {
            return None;
        }
        match self.names.keyword(tok.name()) {
            Keyword::Directive(dir) => Some(dir),
            _ => None,
        }
    }

    /// Parses an expression from the cursor on.
    pub(crate) fn expression(&mut self, c: &mut Cursor<'_>) -> PResult<NodeId> {
        // Fast path for the commonest operand: a lone number or name.
        if let Some(tok) = c.peek()
            && matches!(c.peek_kind_at(1), None | Some(Tok::Comma | Tok::RParen))
        {
            match tok.kind {
                Tok::Number => {
                    c.advance();
                    return Ok(self.prog.node(Node::Const(tok.value as i64)));
                }
                Tok::Ident => {
                    let sym = self.symbol_ref(c)?;
                    return Ok(self.sym_node(sym));
                }
                _ => {}
            }
        }
        self.level7(c, 0)
    }

    /// Precedence climbing: parses operators of level `max_level` and
    /// tighter (2 is tightest among binary operators, 7 is `!`), left to
    /// right, in one loop rather than one recursive call per level.
    fn level7(&mut self, c: &mut Cursor<'_>, depth: u32) -> PResult<NodeId> {
        self.climb(c, 7, depth)
    }

    fn climb(&mut self, c: &mut Cursor<'_>, max_level: u8, depth: u32) -> PResult<NodeId> {
        if depth > MAX_NESTING {
            let span = c.span();
            return Err(self.err("asm::too-deep", span, "expression nested too deeply"));
        }
        let start = c.pos();
        let mut left = match c.peek() {
            Some(tok)
                if max_level == 7
                    && (tok.kind == Tok::Bang || self.directive_of(tok) == Some(Dir::Not)) =>
            {
                c.advance();
                let inner = self.climb(c, 7, depth + 1)?;
                return Ok(self.unary_node(UnaryOp::LogNot, inner));
            }
            _ => self.unary(c, depth + 1)?,
        };
        while let Some(tok) = c.peek() {
            let Some((op, level)) = self.binary_op(tok) else {
                break;
            };
            if level > max_level {
                break;
            }
            c.advance();
            // Left-associative: the right operand binds tighter.
            let right = self.climb(c, level - 1, depth + 1)?;
            if matches!(op, BinaryOp::Div | BinaryOp::Mod)
                && matches!(self.prog.nodes.get(right as usize), Some(Node::Const(0)))
            {
                // Caught here, the caret goes under the division itself
                // rather than the whole operand.
                let span = self.join(c.span_of(start), c.last_span());
                return Err(self.report(
                    diag::error("asm::div-zero", span, "division by zero")
                        .label("the divisor is 0"),
                ));
            }
            left = self.fold(op, left, right);
        }
        Ok(left)
    }

    /// A binary operator and its level.
    fn binary_op(&self, tok: &Token) -> Option<(BinaryOp, u8)> {
        Some(match tok.kind {
            Tok::Star => (BinaryOp::Mul, 2),
            Tok::Slash => (BinaryOp::Div, 2),
            Tok::Amp => (BinaryOp::BitAnd, 2),
            Tok::Caret => (BinaryOp::BitXor, 2),
            Tok::Shl => (BinaryOp::Shl, 2),
            Tok::Shr => (BinaryOp::Shr, 2),
            Tok::Plus => (BinaryOp::Add, 3),
            Tok::Minus => (BinaryOp::Sub, 3),
            Tok::Pipe => (BinaryOp::BitOr, 3),
            Tok::Eq => (BinaryOp::Eq, 4),
            Tok::Ne => (BinaryOp::Ne, 4),
            Tok::Lt => (BinaryOp::Lt, 4),
            Tok::Gt => (BinaryOp::Gt, 4),
            Tok::Le => (BinaryOp::Le, 4),
            Tok::Ge => (BinaryOp::Ge, 4),
            Tok::AndAnd => (BinaryOp::LogAnd, 5),
            Tok::OrOr => (BinaryOp::LogOr, 6),
            Tok::Directive => match self.directive_of(tok)? {
                Dir::Bitand => (BinaryOp::BitAnd, 2),
                Dir::Bitxor => (BinaryOp::BitXor, 2),
                Dir::Shl => (BinaryOp::Shl, 2),
                Dir::Shr => (BinaryOp::Shr, 2),
                Dir::Mod => (BinaryOp::Mod, 2),
                Dir::Bitor => (BinaryOp::BitOr, 3),
                Dir::And => (BinaryOp::LogAnd, 5),
                Dir::Xor => (BinaryOp::LogXor, 5),
                Dir::Or => (BinaryOp::LogOr, 6),
                _ => return None,
            },
            _ => return None,
        })
    }

    /// Builds a binary node, folding two constants on the spot.
    fn fold(&mut self, op: BinaryOp, left: NodeId, right: NodeId) -> NodeId {
        if let (Some(Node::Const(a)), Some(Node::Const(b))) = (
            self.prog.nodes.get(left as usize).copied(),
            self.prog.nodes.get(right as usize).copied(),
        ) && let Ok(value) = op.apply_ca65(a, b)
        {
            return self.prog.node(Node::Const(value));
        }
        self.prog.node(Node::Binary(op, left, right))
    }

    fn unary_node(&mut self, op: UnaryOp, inner: NodeId) -> NodeId {
        if let Some(Node::Const(value)) = self.prog.nodes.get(inner as usize).copied() {
            return self.prog.node(Node::Const(op.apply(value)));
        }
        self.prog.node(Node::Unary(op, inner))
    }

    fn unary(&mut self, c: &mut Cursor<'_>, depth: u32) -> PResult<NodeId> {
        if depth > MAX_NESTING {
            let span = c.span();
            return Err(self.err("asm::too-deep", span, "expression nested too deeply"));
        }
        let Some(tok) = c.peek().copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected an expression here"));
        };
        let op = match tok.kind {
            Tok::Plus => {
                c.advance();
                return self.unary(c, depth + 1);
            }
            Tok::Minus => Some(UnaryOp::Neg),
            Tok::Tilde => Some(UnaryOp::BitNot),
            Tok::Lt => Some(UnaryOp::LoByte),
            Tok::Gt => Some(UnaryOp::HiByte),
            Tok::Caret => Some(UnaryOp::BankByte),
            Tok::Bang => Some(UnaryOp::LogNot),
            Tok::Directive if self.directive_of(&tok) == Some(Dir::Bitnot) => Some(UnaryOp::BitNot),
            Tok::Directive if self.directive_of(&tok) == Some(Dir::Not) => Some(UnaryOp::LogNot),
            _ => None,
        };
        if let Some(op) = op {
            c.advance();
            let inner = self.unary(c, depth + 1)?;
            return Ok(self.unary_node(op, inner));
        }
        self.primary(c, depth)
    }

    fn primary(&mut self, c: &mut Cursor<'_>, depth: u32) -> PResult<NodeId> {
        let tok = c.current();
        match tok.kind {
            Tok::Number => {
                c.advance();
                Ok(self.prog.node(Node::Const(tok.value as i64)))
            }
            Tok::Char => {
                c.advance();
                match usize::try_from(tok.value)
                    .ok()
                    .and_then(|v| self.charmap.get(v))
                {
                    Some(&byte) => Ok(self.prog.node(Node::Const(i64::from(byte)))),
                    None => Err(self.err(
                        "asm::range",
                        tok.span,
                        format!("character U+{:04X} does not fit in a byte", tok.value),
                    )),
                }
            }
            Tok::Str => {
                c.advance();
                let text = self.string_bytes(&tok);
                if text.len() == 1 {
                    let byte = self.charmap[usize::from(text[0])];
                    return Ok(self.prog.node(Node::Const(i64::from(byte))));
                }
                Err(self.err(
                    "asm::syntax",
                    tok.span,
                    "a string is not a number (only a one-character string is)",
                ))
            }
            Tok::Star => {
                c.advance();
                let (chunk, off) = self.here();
                Ok(self.prog.node(Node::Pos { chunk, off }))
            }
            Tok::LParen => {
                c.advance();
                let inner = self.level7(c, depth + 1)?;
                if c.peek_kind() != Some(Tok::RParen) {
                    let span = c.span();
                    let diag = diag::error("asm::syntax", span, "expected `)`")
                        .also(tok.span, "to close this `(`");
                    return Err(self.report(diag));
                }
                c.advance();
                Ok(inner)
            }
            Tok::Unnamed => {
                c.advance();
                let sym = self.unnamed_ref(&tok)?;
                Ok(self.prog.node(Node::Sym(sym)))
            }
            Tok::Local => {
                c.advance();
                let sym = self.cheap_sym(tok.name());
                self.note_ref(sym, tok.span);
                Ok(self.sym_node(sym))
            }
            Tok::Ident | Tok::ColonColon => {
                let sym = self.symbol_ref(c)?;
                Ok(self.sym_node(sym))
            }
            Tok::Directive => self.pseudo_function(c, depth),
            _ => Err(self.err("asm::syntax", tok.span, "expected an expression here")),
        }
    }

    /// A node for a symbol: `.set` variables give their current value.
    fn sym_node(&mut self, sym: SymId) -> NodeId {
        match self.prog.syms[sym as usize].def {
            SymDef::Var(node) => node,
            SymDef::Const(value) => self.prog.node(Node::Const(value)),
            _ => self.prog.node(Node::Sym(sym)),
        }
    }

    fn unnamed_ref(&mut self, tok: &Token) -> PResult<SymId> {
        let count = tok.value as i64;
        let index = if count < 0 {
            let back = count.unsigned_abs() as usize;
            if back > self.symtab.unnamed_count {
                let message = match self.symtab.unnamed_count {
                    0 => "there is no unnamed label `:` before this".to_string(),
                    1 => "there is only one unnamed label before this".to_string(),
                    n => format!("there are only {n} unnamed labels before this"),
                };
                return Err(self.err("asm::undefined", tok.span, message));
            }
            self.symtab.unnamed_count - back
        } else {
            self.symtab.unnamed_count + count as usize - 1
        };
        if index > self.symtab.unnamed_count + 0x1_0000 {
            return Err(self.err(
                "asm::undefined",
                tok.span,
                "unnamed label reference too far ahead",
            ));
        }
        let sym = self.unnamed_sym(index);
        self.note_ref(sym, tok.span);
        Ok(sym)
    }

    /// `name`, `scope::name`, `::name`: a reference, creating the symbol
    /// when it does not exist yet.
    pub(crate) fn symbol_ref(&mut self, c: &mut Cursor<'_>) -> PResult<SymId> {
        let start = c.current().span;
        let mut scope: Option<ScopeId> = None;
        if c.current().kind == Tok::ColonColon {
            scope = Some(GLOBAL_SCOPE);
            c.advance();
        }
        let Some(first) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected a name after `::`"));
        };
        c.advance();
        let mut name = first;
        while c.peek_kind() == Some(Tok::ColonColon) && c.peek_kind_at(1) == Some(Tok::Ident) {
            let outer = name.name();
            let next = match scope {
                None => match self.lookup_scope(outer) {
                    Some(found) => found,
                    None => self.child_scope_or_new(
                        self.symtab.scope,
                        outer,
                        crate::model::ScopeKind::Scope,
                    ),
                },
                Some(s) => self.child_scope_or_new(s, outer, crate::model::ScopeKind::Scope),
            };
            scope = Some(next);
            c.advance();
            name = c.current();
            c.advance();
        }
        let span = self.join(start, name.span);
        match scope {
            None => Ok(self.ref_sym(name.name(), span)),
            Some(s) => {
                let sym = self.sym_in(s, name.name());
                self.note_ref(sym, span);
                Ok(sym)
            }
        }
    }

    /// A symbol name for `.defined`, `.ifdef`...: found, never created.
    pub(crate) fn parse_symbol_name(&mut self, c: &mut Cursor<'_>) -> PResult<Option<SymId>> {
        let Some(tok) = c.peek().copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected a symbol name"));
        };
        if tok.kind == Tok::Local {
            c.advance();
            let sym = self.cheap_sym(tok.name());
            return Ok(Some(sym));
        }
        let mut scope: Option<ScopeId> = None;
        if tok.kind == Tok::ColonColon {
            scope = Some(GLOBAL_SCOPE);
            c.advance();
        }
        let Some(first) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
            let span = c.span();
            return Err(self.err("asm::syntax", span, "expected a symbol name"));
        };
        c.advance();
        let mut name = first.name();
        let mut missing_scope = false;
        while c.peek_kind() == Some(Tok::ColonColon) && c.peek_kind_at(1) == Some(Tok::Ident) {
            let next = match scope {
                None => self.lookup_scope(name),
                Some(s) => self.child_scope(s, name),
            };
            match next {
                Some(s) => scope = Some(s),
                None => missing_scope = true,
            }
            c.advance();
            name = c.current().name();
            c.advance();
        }
        if missing_scope {
            return Ok(None);
        }
        Ok(match scope {
            Some(s) => self.find_sym(s, name),
            None => {
                let mut s = self.symtab.scope;
                loop {
                    if let Some(sym) = self.find_sym(s, name) {
                        break Some(sym);
                    }
                    if s == GLOBAL_SCOPE {
                        break None;
                    }
                    s = self.prog.scopes[s as usize].parent;
                }
            }
        })
    }

    pub(crate) fn expect(&mut self, c: &mut Cursor<'_>, kind: Tok, what: &str) -> PResult<()> {
        if c.peek_kind() == Some(kind) {
            c.advance();
            return Ok(());
        }
        let span = c.span();
        Err(self.err("asm::syntax", span, format!("expected {what}")))
    }

    fn pseudo_function(&mut self, c: &mut Cursor<'_>, depth: u32) -> PResult<NodeId> {
        let head = c.current();
        let Some(dir) = self.directive_of(&head) else {
            let name = self.names.name(head.name()).to_string();
            return Err(self.err(
                "asm::unknown-directive",
                head.span,
                format!("`{name}` is not a directive this assembler knows"),
            ));
        };
        c.advance();
        let bool_node = |asm: &mut Self, value: bool| asm.prog.node(Node::Const(i64::from(value)));
        match dir {
            Dir::Lobyte | Dir::Hibyte | Dir::Bankbyte | Dir::Loword | Dir::Hiword | Dir::Const => {
                self.expect(c, Tok::LParen, "`(`")?;
                let inner = self.level7(c, depth + 1)?;
                self.expect(c, Tok::RParen, "`)`")?;
                Ok(match dir {
                    Dir::Lobyte => self.unary_node(UnaryOp::LoByte, inner),
                    Dir::Hibyte => self.unary_node(UnaryOp::HiByte, inner),
                    Dir::Bankbyte => self.unary_node(UnaryOp::BankByte, inner),
                    Dir::Loword => {
                        let mask = self.prog.node(Node::Const(0xFFFF));
                        self.fold(BinaryOp::BitAnd, inner, mask)
                    }
                    Dir::Hiword => {
                        let sixteen = self.prog.node(Node::Const(16));
                        let shifted = self.fold(BinaryOp::Shr, inner, sixteen);
                        let mask = self.prog.node(Node::Const(0xFFFF));
                        self.fold(BinaryOp::BitAnd, shifted, mask)
                    }
                    _ => {
                        let constant = matches!(self.prog.eval(inner), Ok(Value::Const(_)));
                        bool_node(self, constant)
                    }
                })
            }
            Dir::Defined | Dir::Referenced => {
                self.expect(c, Tok::LParen, "`(`")?;
                let sym = self.parse_symbol_name(c)?;
                self.expect(c, Tok::RParen, "`)`")?;
                let answer = sym.is_some_and(|s| {
                    let sym = &self.prog.syms[s as usize];
                    if dir == Dir::Defined {
                        sym.is_defined()
                    } else {
                        sym.ref_loc.is_some()
                    }
                });
                Ok(bool_node(self, answer))
            }
            Dir::Blank => {
                self.expect(c, Tok::LParen, "`(`")?;
                let mut nesting = 0usize;
                let mut count = 0usize;
                while let Some(tok) = c.peek() {
                    match tok.kind {
                        Tok::LParen => nesting += 1,
                        Tok::RParen if nesting == 0 => break,
                        Tok::RParen => nesting -= 1,
                        Tok::LBrace | Tok::RBrace => {
                            c.advance();
                            continue;
                        }
                        _ => {}
                    }
                    count += 1;
                    c.advance();
                }
                self.expect(c, Tok::RParen, "`)`")?;
                Ok(bool_node(self, count == 0))
            }
            // The ca65 this assembler answers for: Debian's, which calls
            // itself 2.18 (major * $100 + minor * $10).
            Dir::Version => Ok(self.prog.node(Node::Const(CA65_VERSION))),
            Dir::Tcount => {
                let count = self.tcount(c)?;
                Ok(self.prog.node(Node::Const(count)))
            }
            Dir::Match | Dir::Xmatch => {
                let answer = self.token_match(c, dir == Dir::Xmatch)?;
                Ok(bool_node(self, answer))
            }
            // The instruction set now in use, as `.macpack cpu`'s masks
            // spell it.
            Dir::Cpu => {
                let mask = if self.cpu_x {
                    crate::macpack::CPU_6502X
                } else {
                    crate::macpack::CPU_6502
                };
                Ok(self.prog.node(Node::Const(mask)))
            }
            Dir::Paramcount => {
                let count = self
                    .input
                    .frames
                    .iter()
                    .rev()
                    .find_map(|frame| match frame {
                        Frame::Macro { args, .. } => Some(args.len()),
                        _ => None,
                    });
                match count {
                    Some(count) => Ok(self.prog.node(Node::Const(count as i64))),
                    None => Err(self.err(
                        "asm::syntax",
                        head.span,
                        "`.paramcount` is only meaningful inside a macro",
                    )),
                }
            }
            Dir::Strlen => {
                self.expect(c, Tok::LParen, "`(`")?;
                let Some(tok) = c.peek().filter(|t| t.kind == Tok::Str).copied() else {
                    let span = c.span();
                    return Err(self.err("asm::syntax", span, "expected a string"));
                };
                c.advance();
                self.expect(c, Tok::RParen, "`)`")?;
                let len = self.string_bytes(&tok).len();
                Ok(self.prog.node(Node::Const(len as i64)))
            }
            Dir::Strat => {
                // `.strat(string, index)`: the character at `index` (from
                // 0), through the character map as a `.byte` string is.
                self.expect(c, Tok::LParen, "`(`")?;
                let Some(tok) = c.peek().filter(|t| t.kind == Tok::Str).copied() else {
                    let span = c.span();
                    return Err(self.err("asm::syntax", span, "expected a string"));
                };
                c.advance();
                self.expect(c, Tok::Comma, "`,` and the index")?;
                let at = c.span();
                let index = self.const_expr(c, "the `.strat` index")?;
                self.expect(c, Tok::RParen, "`)`")?;
                let bytes = self.string_bytes(&tok);
                let Some(&byte) = usize::try_from(index).ok().and_then(|i| bytes.get(i)) else {
                    return Err(self.report(crate::resolver::range_diag(
                        at,
                        "the `.strat` index",
                        index,
                        (0, bytes.len() as i64 - 1),
                    )));
                };
                Ok(self
                    .prog
                    .node(Node::Const(i64::from(self.charmap[usize::from(byte)]))))
            }
            // `.addrsize(name)` (`.feature addrsize`): 1 for zero page, 2
            // absolute, 3 far, 0 unknown, as ca65's.
            Dir::Addrsize if self.features.addrsize => {
                self.expect(c, Tok::LParen, "`(`")?;
                let sym = self.symbol_ref(c)?;
                self.expect(c, Tok::RParen, "`)`")?;
                let size = self.address_size(sym);
                Ok(self.prog.node(Node::Const(size)))
            }
            Dir::Sizeof => {
                self.expect(c, Tok::LParen, "`(`")?;
                let node = self.sizeof(c)?;
                self.expect(c, Tok::RParen, "`)`")?;
                Ok(node)
            }
            _ => {
                let name = self.names.name(head.name()).to_string();
                Err(self.err(
                    "asm::syntax",
                    head.span,
                    format!("`{name}` cannot be used in an expression"),
                ))
            }
        }
    }

    /// A symbol's address size as ca65 numbers it.
    fn address_size(&mut self, sym: SymId) -> i64 {
        let by_value = |value: i64| match value {
            0..=0xFF => 1,
            0x100..=0xFFFF => 2,
            _ => 3,
        };
        match self.prog.syms[sym as usize].def {
            SymDef::Import { zp } => {
                if zp {
                    1
                } else {
                    2
                }
            }
            SymDef::Undefined => 0,
            _ => match self.prog.eval_sym(sym) {
                Ok(Value::Const(value)) => by_value(value),
                Ok(Value::Addr {
                    base: crate::expr::Base::Sec(seg),
                    ..
                }) if self.prog.segs[seg as usize].zp => 1,
                Ok(_) => 2,
                Err(_) => 0,
            },
        }
    }

    /// `.sizeof(name)`: the size of a struct, union, enum or scope.
    fn sizeof(&mut self, c: &mut Cursor<'_>) -> PResult<NodeId> {
        let start = c.span();
        let mut scope: Option<ScopeId> = None;
        let mut absolute = false;
        if c.peek_kind() == Some(Tok::ColonColon) {
            absolute = true;
            c.advance();
        }
        loop {
            let Some(tok) = c.peek().filter(|t| t.kind == Tok::Ident).copied() else {
                let span = c.span();
                return Err(self.err("asm::syntax", span, "expected a struct or scope name"));
            };
            c.advance();
            let found = match (scope, absolute) {
                (None, false) => self.lookup_scope(tok.name()),
                (None, true) => self.child_scope(GLOBAL_SCOPE, tok.name()),
                (Some(s), _) => self.child_scope(s, tok.name()),
            };
            let Some(found) = found else {
                // A struct member's size (`.sizeof(HDR::JUMPTAB)`).
                if let Some(outer) = scope
                    && let Some(sym) = self.find_sym(outer, tok.name())
                    && let Some(&size) = self.label_sizes.get(&sym)
                {
                    return Ok(self.prog.node(Node::Const(size)));
                }
                // A label's size: what its line emitted.
                if scope.is_none() && !absolute {
                    let mut at = self.symtab.scope;
                    loop {
                        if let Some(sym) = self.find_sym(at, tok.name())
                            && let Some(&size) = self.label_sizes.get(&sym)
                        {
                            return Ok(self.prog.node(Node::Const(size)));
                        }
                        if at == GLOBAL_SCOPE {
                            break;
                        }
                        at = self.prog.scopes[at as usize].parent;
                    }
                }
                let name = self.names.name(tok.name()).to_string();
                return Err(self.err(
                    "asm::undefined",
                    self.join(start, tok.span),
                    format!("`.sizeof` needs a struct, union, enum, scope or label; `{name}` is none of these (yet)"),
                ));
            };
            scope = Some(found);
            if c.peek_kind() == Some(Tok::ColonColon) {
                c.advance();
                continue;
            }
            break;
        }
        let scope = scope.unwrap_or(GLOBAL_SCOPE);
        let info = &self.prog.scopes[scope as usize];
        if let Some(size) = info.size {
            return Ok(self.prog.node(Node::Const(size)));
        }
        Ok(self.prog.node(Node::ScopeSize(scope)))
    }

    /// The bytes between a string token's quotes.
    pub(crate) fn string_bytes(&self, tok: &Token) -> Vec<u8> {
        let text = self.files.text(tok.span.file);
        let start = (tok.span.start as usize + 1).min(text.len());
        let end = (tok.span.end as usize)
            .saturating_sub(1)
            .clamp(start, text.len());
        if tok.value == crate::lexer::STRING_ESCAPED {
            return crate::lexer::unescape(&text[start..end]);
        }
        text[start..end].to_vec()
    }

    /// An expression that must be a constant now (`.if`, `.res`, `.org`...).
    pub(crate) fn const_expr(&mut self, c: &mut Cursor<'_>, what: &str) -> PResult<i64> {
        let start = c.pos();
        let node = self.expression(c)?;
        let span = self.join(c.span_of(start), c.last_span());
        match self.eval_now(node, span) {
            Ok(Value::Const(value)) => Ok(value),
            Ok(_) => {
                let diag = diag::error(
                    "asm::not-constant",
                    span,
                    format!("{what} needs a constant, but this is an address the linker decides"),
                )
                .help("labels are constants only after `.org`; compute this from constants or label differences");
                Err(self.report(diag))
            }
            Err(EvalErr::NotYet(Some(sym))) => {
                let name = self.sym_name(sym);
                let at = self.name_within(c.tokens(), sym, span).unwrap_or(span);
                Err(self.err(
                    "asm::not-constant",
                    at,
                    format!("{what} needs a value known here, but `{name}` is not defined yet"),
                ))
            }
            Err(EvalErr::NotYet(None)) => Err(self.err(
                "asm::not-constant",
                span,
                format!(
                    "{what} needs a value known here, but it depends on addresses not fixed yet"
                ),
            )),
            Err(error) => Err(self.eval_error(error, span)),
        }
    }

    /// Evaluates `node` where its value is needed at once: names a scope
    /// has not defined yet take their outer namesake's value, and each
    /// such use is remembered (at `span`) so that a later definition in
    /// the scope is an error rather than a silent disagreement with ca65.
    pub(crate) fn eval_now(&mut self, node: NodeId, span: Span) -> Result<Value, EvalErr> {
        if self.prog.outer.is_empty() {
            return self.prog.eval(node);
        }
        self.prog.outer_fallback = true;
        let value = self.prog.eval(node);
        self.prog.outer_fallback = false;
        if !self.prog.outer_hits.is_empty() {
            let loc = self.loc(span);
            for sym in std::mem::take(&mut self.prog.outer_hits) {
                if let Some(use_) = self.prog.outer.get_mut(&sym) {
                    use_.used.get_or_insert(loc);
                }
            }
        }
        value
    }

    /// Where `sym` is named inside `span` on the current line, if it is:
    /// the sub-expression an error about that symbol points at.
    fn name_within(&self, toks: &[Token], sym: SymId, span: Span) -> Option<Span> {
        let name = self.prog.syms.get(sym as usize)?.name;
        let token = toks.iter().find(|tok| {
            tok.kind == Tok::Ident
                && tok.name() == name
                && tok.span.file == span.file
                && tok.span.start >= span.start
                && tok.span.end <= span.end
        });
        if let Some(token) = token {
            return Some(token.span);
        }
        // Reported after the line was read (layout): find the name, as a
        // whole word, in the span's text.
        let text = self.files.text(span.file);
        let (start, end) = (span.start as usize, (span.end as usize).min(text.len()));
        let needle = self.names.name(name).as_bytes();
        let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_' || b == b'@';
        let within = text.get(start..end)?;
        (0..within.len().saturating_sub(needle.len()) + 1)
            .filter(|&at| within[at..].starts_with(needle))
            .find(|&at| {
                let before = at.checked_sub(1).map(|i| within[i]);
                let after = within.get(at + needle.len()).copied();
                !needle.is_empty() && !before.is_some_and(word) && !after.is_some_and(word)
            })
            .map(|at| Span {
                file: span.file,
                start: (start + at) as u32,
                end: (start + at + needle.len()) as u32,
            })
    }

    /// Reports an evaluation failure at `span` (narrowed to the symbol at
    /// fault when the failure names one).
    pub(crate) fn eval_error(&mut self, error: EvalErr, span: Span) -> Reported {
        let span = match error {
            EvalErr::NotYet(Some(sym)) | EvalErr::Circular(sym) => self
                .name_within(&self.input.toks, sym, span)
                .unwrap_or(span),
            _ => span,
        };
        let (code, message, help) = match error {
            EvalErr::Undefined(_) => return Reported,
            EvalErr::NotYet(Some(sym)) => (
                "asm::not-constant",
                format!("`{}` is not defined yet", self.sym_name(sym)),
                None,
            ),
            EvalErr::NotYet(None) => (
                "asm::not-constant",
                "this value depends on addresses not fixed yet".to_string(),
                None,
            ),
            EvalErr::DivZero => ("asm::div-zero", "division by zero".to_string(), None),
            EvalErr::NotRelocatable => (
                "asm::not-relocatable",
                format!(
                    "`{}` uses an address in a way no relocation can express",
                    self.files.snippet(span)
                ),
                Some(
                    "the linker can add a constant to an address, or take its `<` / `>` / `^` byte; other arithmetic needs constants (use `.org`, or label differences in one segment)"
                        .to_string(),
                ),
            ),
            EvalErr::Circular(sym) => (
                "asm::circular",
                format!("`{}` is defined in terms of itself", self.sym_name(sym)),
                None,
            ),
            EvalErr::TooComplex => (
                "asm::too-deep",
                "this expression is too deeply nested to evaluate".to_string(),
                None,
            ),
        };
        let mut diag = diag::error(code, span, message);
        if let Some(help) = help {
            diag = diag.help(help);
        }
        self.report(diag)
    }
}
