//! Expression values and evaluation.
//!
//! A value is a constant, an address relative to a segment or an import
//! (what a relocation can express: symbol + constant), a byte of such an
//! address (`<`, `>`, `^`), or, while reading the source, a position in a
//! chunk not yet placed. Every constant operation goes through
//! [`UnaryOp::apply`] / [`BinaryOp::apply`] from `isa::objfmt`, the same
//! code the linker uses for deferred assertions.

use isa::objfmt::{BinaryOp, UnaryOp};

use crate::model::{ChunkId, Node, NodeId, Program, SegId, SymDef, SymId};

/// Which byte of an address.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sel {
    Lo,
    Hi,
    Bank,
}

impl Sel {
    /// What one unit of the selected byte is worth in the address.
    fn scale(self) -> i64 {
        match self {
            Sel::Lo => 1,
            Sel::Hi => 0x100,
            Sel::Bank => 0x1_0000,
        }
    }
}

/// What an address is relative to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Base {
    Sec(SegId),
    Ext(SymId),
}

/// The value of an expression.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Value {
    Const(i64),
    /// `base + off`.
    Addr {
        base: Base,
        off: i64,
    },
    /// A position in a chunk whose start is not known yet (front end only).
    Chunk {
        chunk: ChunkId,
        off: i64,
    },
    /// One byte of `base + off`.
    Byte {
        sel: Sel,
        base: Base,
        off: i64,
    },
}

/// Why an expression has no value (yet).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EvalErr {
    /// Needs something defined later or a position not yet known.
    NotYet(Option<SymId>),
    /// A symbol that was never defined (reported once, elsewhere).
    Undefined(SymId),
    DivZero,
    /// An operation on an address that no relocation can express.
    NotRelocatable,
    /// A symbol whose definition refers to itself.
    Circular(SymId),
    /// Too deep or too long to evaluate.
    TooComplex,
}

const MAX_DEPTH: u32 = 200;

fn add(a: i64, b: i64) -> i64 {
    BinaryOp::Add.apply(a, b).unwrap_or(0)
}

fn sub(a: i64, b: i64) -> i64 {
    BinaryOp::Sub.apply(a, b).unwrap_or(0)
}

fn mul(a: i64, b: i64) -> i64 {
    BinaryOp::Mul.apply(a, b).unwrap_or(0)
}

impl Program {
    /// Evaluates `node`. Before layout (`self.placed == false`) positions
    /// in unplaced chunks stay symbolic and unknown symbols give
    /// [`EvalErr::NotYet`].
    pub(crate) fn eval(&mut self, node: NodeId) -> Result<Value, EvalErr> {
        self.budget = 1_000_000;
        self.eval_at(node, 0)
    }

    /// Evaluates a symbol's value.
    pub(crate) fn eval_sym(&mut self, sym: SymId) -> Result<Value, EvalErr> {
        self.budget = 1_000_000;
        self.sym_value(sym, 0)
    }

    fn eval_at(&mut self, node: NodeId, depth: u32) -> Result<Value, EvalErr> {
        if depth > MAX_DEPTH || self.budget == 0 {
            return Err(EvalErr::TooComplex);
        }
        self.budget -= 1;
        let Some(&n) = self.nodes.get(node as usize) else {
            return Err(EvalErr::TooComplex);
        };
        match n {
            Node::Const(value) => Ok(Value::Const(value)),
            Node::Sym(sym) => self.sym_value(sym, depth + 1),
            Node::Pos { chunk, off } => Ok(self.position(chunk, i64::from(off))),
            Node::Unary(op, inner) => {
                let value = self.eval_at(inner, depth + 1)?;
                unary(op, value)
            }
            Node::Binary(op, left, right) => {
                let left = self.eval_at(left, depth + 1);
                // `.and`/`&&` with a false left side and `.or`/`||` with a
                // true one are settled without their right side, as in
                // ca65 (`.if .def(x) .and x < 10` with `x` not defined).
                match (op, &left) {
                    (BinaryOp::LogAnd, Ok(Value::Const(0))) => return Ok(Value::Const(0)),
                    (BinaryOp::LogOr, Ok(Value::Const(v))) if *v != 0 => {
                        return Ok(Value::Const(1));
                    }
                    _ => {}
                }
                let right = self.eval_at(right, depth + 1);
                // A hard error on either side wins over "not yet".
                let (left, right) = match (left, right) {
                    (Ok(l), Ok(r)) => (l, r),
                    (Err(e), Err(EvalErr::NotYet(_))) | (Err(EvalErr::NotYet(_)), Err(e)) => {
                        return Err(e);
                    }
                    (Err(e), _) | (_, Err(e)) => return Err(e),
                };
                self.binary(op, left, right)
            }
            Node::ScopeSize(scope) => {
                let Some(info) = self.scopes.get(scope as usize) else {
                    return Err(EvalErr::TooComplex);
                };
                if let Some(size) = info.size {
                    return Ok(Value::Const(size));
                }
                match (info.start, info.end) {
                    (Some((c1, o1)), Some((c2, o2))) => {
                        let start = self.position(c1, i64::from(o1));
                        let end = self.position(c2, i64::from(o2));
                        self.binary(BinaryOp::Sub, end, start)
                    }
                    _ if self.placed => Ok(Value::Const(0)),
                    _ => Err(EvalErr::NotYet(None)),
                }
            }
        }
    }

    /// The value of a position, as precisely as is known now.
    pub(crate) fn position(&self, chunk: ChunkId, off: i64) -> Value {
        let Some(c) = self.chunks.get(chunk as usize) else {
            return Value::Const(0);
        };
        if self.placed {
            return if c.org {
                Value::Const(add(c.abs, off))
            } else {
                Value::Addr {
                    base: Base::Sec(c.seg),
                    off: add(i64::from(c.start), off),
                }
            };
        }
        if c.org {
            match c.known_abs {
                Some(abs) => Value::Const(add(abs, off)),
                None => Value::Chunk { chunk, off },
            }
        } else {
            match c.known_start {
                Some(start) => Value::Addr {
                    base: Base::Sec(c.seg),
                    off: add(i64::from(start), off),
                },
                None => Value::Chunk { chunk, off },
            }
        }
    }

    fn sym_value(&mut self, sym: SymId, depth: u32) -> Result<Value, EvalErr> {
        let Some(s) = self.syms.get(sym as usize) else {
            return Err(EvalErr::TooComplex);
        };
        match s.def {
            SymDef::Undefined => {
                if self.placed {
                    Err(EvalErr::Undefined(sym))
                } else if self.outer_fallback
                    && let Some(outer) = self.outer.get(&sym).map(|o| o.outer)
                {
                    self.outer_hits.push(sym);
                    self.sym_value(outer, depth + 1)
                } else {
                    Err(EvalErr::NotYet(Some(sym)))
                }
            }
            SymDef::Const(value) => Ok(Value::Const(value)),
            SymDef::Label { chunk, off } => Ok(self.position(chunk, i64::from(off))),
            SymDef::Import { .. } => Ok(Value::Addr {
                base: Base::Ext(sym),
                off: 0,
            }),
            SymDef::Alias(other) => self.sym_value(other, depth + 1),
            SymDef::Var(node) => self.eval_at(node, depth + 1),
            SymDef::Expr(node) => {
                let memo = s.memo.as_deref().copied().unwrap_or_default();
                if self.outer_fallback && !self.placed {
                    // A value borrowed from outer names is no scope's
                    // final value: not kept in the memo.
                    if let Some(value) = memo.front {
                        return Ok(value);
                    }
                    if s.busy {
                        return Err(EvalErr::Circular(sym));
                    }
                    self.syms[sym as usize].busy = true;
                    let result = self.eval_at(node, depth + 1);
                    self.syms[sym as usize].busy = false;
                    return result;
                }
                if !self.placed {
                    if let Some(value) = memo.front {
                        return Ok(value);
                    }
                    // "Not yet" stays true until another symbol is defined:
                    // without this a chain of forward definitions could be
                    // re-evaluated exponentially often.
                    if let Some((defs, result)) = memo.result
                        && defs == self.defs
                    {
                        return result;
                    }
                } else if let Some((stamp, result)) = memo.result
                    && stamp == self.stamp
                {
                    return result;
                }
                if s.busy {
                    return Err(EvalErr::Circular(sym));
                }
                self.syms[sym as usize].busy = true;
                let result = self.eval_at(node, depth + 1);
                let (placed, stamp, defs) = (self.placed, self.stamp, self.defs);
                let s = &mut self.syms[sym as usize];
                s.busy = false;
                let memo = s.memo.get_or_insert_with(Box::default);
                memo.result = Some((if placed { stamp } else { defs }, result));
                if !placed
                    && let Ok(value @ (Value::Const(_) | Value::Addr { .. } | Value::Byte { .. })) =
                        result
                {
                    // Front-end values without unplaced positions are final.
                    memo.front = Some(value);
                }
                result
            }
        }
    }

    pub(crate) fn binary(&self, op: BinaryOp, left: Value, right: Value) -> Result<Value, EvalErr> {
        use Value::{Addr, Byte, Chunk, Const};
        let not_yet = |v: &Value| matches!(v, Chunk { .. });
        match (op, left, right) {
            (_, Const(a), Const(b)) => op.apply_ca65(a, b).map(Const).map_err(|_| EvalErr::DivZero),
            (BinaryOp::Add, Addr { base, off }, Const(k))
            | (BinaryOp::Add, Const(k), Addr { base, off }) => Ok(Addr {
                base,
                off: add(off, k),
            }),
            (BinaryOp::Sub, Addr { base, off }, Const(k)) => Ok(Addr {
                base,
                off: sub(off, k),
            }),
            (BinaryOp::Add, Chunk { chunk, off }, Const(k))
            | (BinaryOp::Add, Const(k), Chunk { chunk, off }) => Ok(Chunk {
                chunk,
                off: add(off, k),
            }),
            (BinaryOp::Sub, Chunk { chunk, off }, Const(k)) => Ok(Chunk {
                chunk,
                off: sub(off, k),
            }),
            (BinaryOp::Add, Byte { sel, base, off }, Const(k))
            | (BinaryOp::Add, Const(k), Byte { sel, base, off }) => Ok(Byte {
                sel,
                base,
                off: add(off, mul(k, sel.scale())),
            }),
            (BinaryOp::Sub, Byte { sel, base, off }, Const(k)) => Ok(Byte {
                sel,
                base,
                off: sub(off, mul(k, sel.scale())),
            }),
            (BinaryOp::Sub, Addr { base: b1, off: o1 }, Addr { base: b2, off: o2 }) if b1 == b2 => {
                Ok(Const(sub(o1, o2)))
            }
            (BinaryOp::Sub, Chunk { chunk: c1, off: o1 }, Chunk { chunk: c2, off: o2 })
                if c1 == c2 =>
            {
                Ok(Const(sub(o1, o2)))
            }
            (_, l, r) if not_yet(&l) || not_yet(&r) => Err(EvalErr::NotYet(None)),
            _ => Err(EvalErr::NotRelocatable),
        }
    }
}

fn unary(op: UnaryOp, value: Value) -> Result<Value, EvalErr> {
    let sel = match op {
        UnaryOp::LoByte => Some(Sel::Lo),
        UnaryOp::HiByte => Some(Sel::Hi),
        UnaryOp::BankByte => Some(Sel::Bank),
        _ => None,
    };
    match (value, sel) {
        (Value::Const(v), _) => Ok(Value::Const(op.apply(v))),
        (Value::Addr { base, off }, Some(sel)) => Ok(Value::Byte { sel, base, off }),
        (Value::Byte { .. }, Some(Sel::Lo)) => Ok(value),
        (Value::Byte { .. }, Some(_)) => Ok(Value::Const(0)),
        (Value::Chunk { .. }, _) => Err(EvalErr::NotYet(None)),
        _ => Err(EvalErr::NotRelocatable),
    }
}
