//! `.if` and its family, `.else`, `.elseif`, `.endif`: the stack of
//! conditions the expander consults on every line.

use super::*;

impl<'a> Asm<'a> {
    /// `c` is at the directive.
    pub(crate) fn conditional(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<()> {
        let head = c.current();
        let base = self.input.frames.last().map_or(0, Frame::conds);
        match dir {
            Dir::Else | Dir::Elseif => {
                if self.input.conds.len() <= base {
                    return Err(self.err(
                        "asm::unbalanced",
                        head.span,
                        format!("`{}` without `.if`", self.names.name(head.name())),
                    ));
                }
                let cond = *self.input.conds.last().unwrap_or(&Cond {
                    span: head.span,
                    parent_active: false,
                    active: false,
                    taken: true,
                    seen_else: false,
                });
                if cond.seen_else {
                    let diag = diag::error(
                        "asm::unbalanced",
                        head.span,
                        format!("`{}` after `.else`", self.names.name(head.name())),
                    )
                    .also(cond.span, "in this `.if`");
                    return Err(self.report(diag));
                }
                let mut next = cond;
                if dir == Dir::Else {
                    next.active = cond.parent_active && !cond.taken;
                    next.taken = true;
                    next.seen_else = true;
                } else if !cond.parent_active || cond.taken {
                    next.active = false;
                } else {
                    c.advance();
                    let value = self.const_expr(c, "`.elseif`")?;
                    self.expect_end(c)?;
                    next.active = value != 0;
                    next.taken = next.active;
                }
                if let Some(top) = self.input.conds.last_mut() {
                    *top = next;
                }
                Ok(())
            }
            Dir::Endif => {
                if self.input.conds.len() <= base {
                    return Err(self.err("asm::unbalanced", head.span, "`.endif` without `.if`"));
                }
                self.input.conds.pop();
                c.advance();
                self.expect_end(c)
            }
            _ => {
                let truth = self.condition(dir, c);
                let active = truth.unwrap_or(false);
                self.input.conds.push(Cond {
                    span: head.span,
                    parent_active: true,
                    active,
                    // A failed condition takes no branch but also enables
                    // none, so errors do not cascade.
                    taken: active || truth.is_err(),
                    seen_else: false,
                });
                truth.map(|_| ())
            }
        }
    }

    fn condition(&mut self, dir: Dir, c: &mut Cursor<'_>) -> PResult<bool> {
        c.advance();
        let result = match dir {
            Dir::If => self.const_expr(c, "`.if`")? != 0,
            Dir::Ifdef | Dir::Ifndef | Dir::Ifref | Dir::Ifnref => {
                let sym = self.parse_symbol_name(c)?;
                let defined = sym.is_some_and(|s| {
                    if matches!(dir, Dir::Ifref | Dir::Ifnref) {
                        self.prog.syms[s as usize].ref_loc.is_some()
                    } else {
                        self.prog.syms[s as usize].is_defined()
                    }
                });
                defined == matches!(dir, Dir::Ifdef | Dir::Ifref)
            }
            Dir::Ifblank | Dir::Ifnblank => {
                let blank = c.is_end();
                c.advance_by(c.rest().len());
                blank == (dir == Dir::Ifblank)
            }
            Dir::Ifconst => {
                let expr = self.expression(c)?;
                matches!(self.prog.eval(expr), Ok(crate::expr::Value::Const(_)))
            }
            Dir::Ifp02 => true,
            _ => false,
        };
        self.expect_end(c)?;
        Ok(result)
    }
}
