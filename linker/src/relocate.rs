//! Applying relocations, with lld's MOS semantics (lld/ELF/Arch/MOS.cpp in
//! llvm-mos) and range checks that name the source line.
//!
//! With S the symbol's value, A the addend and P the address of the
//! patched byte:
//!
//! | type | writes | check |
//! |---|---|---|
//! | `R_MOS_IMM8` | S + A | fits -128..=255 |
//! | `R_MOS_ADDR8` | S + A | (S + A) & $FFFF is $00-$FF (lld also accepts $FF80-$FFFF as negative; we do not) |
//! | `R_MOS_ADDR16` | S + A, 16-bit little-endian | none (high bits are often a bank) |
//! | `R_MOS_ADDR16_LO` / `_HI` | bits 0-7 / 8-15 | none |
//! | `R_MOS_PCREL_8` | S + A - P - 1 | fits -128..=127 |
//! | `R_MOS_ADDR24` | S + A, 24-bit little-endian | fits 0..=$FFFFFF |
//! | `R_MOS_ADDR24_BANK` | bits 16-23 | S + A fits 0..=$FFFFFF |
//! | `R_MOS_FK_DATA_4` / `_8` | S + A, 32 / 64-bit little-endian | none |

use isa::elf as mos;
use isa::objfmt::{EvalError, FieldKind};

use crate::error::Error;
use crate::input::{Definition, Object};
use crate::place::Placed;
use crate::source::SourceProvider;

/// Patches every relocation into `segments`' bytes; range errors go to
/// `errors`. References whose symbol has no value were reported already
/// (undefined, or in an unplaced section) and are skipped.
pub(crate) fn apply(
    objects: &[Object],
    values: &[Vec<Option<i64>>],
    segments: &mut [Placed],
    sources: &dyn SourceProvider,
    errors: &mut Vec<Error>,
) {
    for segment in segments.iter_mut() {
        let base = segment.run;
        let has_bytes = !segment.bytes.is_empty();
        let Placed {
            fragments,
            bytes: segment_bytes,
            ..
        } = segment;
        for fragment in fragments.iter() {
            let object = &objects[fragment.object];
            let section = &object.sections[fragment.section];
            for reloc in &section.relocs {
                let symbol = if reloc.symbol == 0 {
                    Some(0)
                } else {
                    values[fragment.object][reloc.symbol]
                };
                let Some(symbol_value) = symbol else { continue };
                let value = symbol_value.wrapping_add(reloc.addend);
                let at_offset = fragment.offset + u64::from(reloc.offset);
                let p = (base + at_offset) as i64;
                let describe = |with_value: bool| {
                    let entry = &object.symbols[reloc.symbol];
                    let name = if entry.is_section_or_file || entry.name.is_empty() {
                        match entry.definition {
                            Definition::Section(target, _) => object.sections[target].name.clone(),
                            _ => "address".to_owned(),
                        }
                    } else {
                        format!("`{}`", entry.name)
                    };
                    let addend = match reloc.addend {
                        0 => String::new(),
                        a if a > 0 => format!("+{a}"),
                        a => a.to_string(),
                    };
                    if with_value {
                        format!("{name}{addend} (${:04X})", value & 0xFFFF_FFFF)
                    } else {
                        format!("{name}{addend}")
                    }
                };
                let place = || object.place_of_byte(fragment.section, reloc.offset);
                let patch: Option<Vec<u8>> = match reloc.r_type {
                    mos::R_MOS_NONE => None,
                    mos::R_MOS_IMM8 => {
                        if !(-128..=255).contains(&value) {
                            let place = place();
                            let (src, span) = place.snippet(sources);
                            errors.push(Error::ValueRange {
                                kind: relocation_name(reloc.r_type),
                                target: describe(false),
                                value,
                                range: "8 bits (-128 to 255)",
                                at: place.text,
                                src,
                                span,
                            });
                        }
                        Some(vec![value as u8])
                    }
                    mos::R_MOS_ADDR8 => {
                        let address = value & 0xFFFF;
                        if address > 0xFF {
                            let place = place();
                            let (src, span) = place.snippet(sources);
                            errors.push(Error::ZeroPageRange {
                                target: describe(false),
                                at: place.text,
                                value: address,
                                src,
                                span,
                            });
                        }
                        Some(vec![address as u8])
                    }
                    mos::R_MOS_ADDR16 => Some((value as u16).to_le_bytes().to_vec()),
                    mos::R_MOS_ADDR16_LO => Some(vec![value as u8]),
                    mos::R_MOS_ADDR16_HI => Some(vec![(value >> 8) as u8]),
                    mos::R_MOS_PCREL_8 => {
                        let distance = value.wrapping_sub(p).wrapping_sub(1);
                        if !(-128..=127).contains(&distance) {
                            let place = place();
                            let (src, span) = place.snippet(sources);
                            errors.push(Error::BranchRange {
                                target: describe(true),
                                at: place.text,
                                distance,
                                src,
                                span,
                            });
                        }
                        Some(vec![distance as u8])
                    }
                    mos::R_MOS_ADDR24 | mos::R_MOS_ADDR24_BANK => {
                        if !(0..=0xFF_FFFF).contains(&value) {
                            let place = place();
                            let (src, span) = place.snippet(sources);
                            errors.push(Error::ValueRange {
                                kind: relocation_name(reloc.r_type),
                                target: describe(false),
                                value,
                                range: "24 bits (0 to $FFFFFF)",
                                at: place.text,
                                src,
                                span,
                            });
                        }
                        if reloc.r_type == mos::R_MOS_ADDR24 {
                            Some((value as u32).to_le_bytes()[..3].to_vec())
                        } else {
                            Some(vec![(value >> 16) as u8])
                        }
                    }
                    mos::R_MOS_FK_DATA_4 => Some((value as u32).to_le_bytes().to_vec()),
                    mos::R_MOS_FK_DATA_8 => Some(value.to_le_bytes().to_vec()),
                    // `input` accepts no other type.
                    _ => None,
                };
                if let (Some(bytes), true) = (patch, has_bytes) {
                    let start = at_offset as usize;
                    if let Some(target) = segment_bytes.get_mut(start..start + bytes.len()) {
                        target.copy_from_slice(&bytes);
                    }
                }
            }
        }
    }
}

/// Writes every field the objects compute from expressions into
/// `segments`' bytes (after relocation: a field may overlap nothing else),
/// range-checked as ld65 checks them. Expressions naming a symbol that was
/// reported undefined are skipped.
pub(crate) fn apply_fields(
    objects: &[Object],
    values: &[Vec<Option<i64>>],
    unresolved: &[Vec<bool>],
    segments: &mut [Placed],
    sources: &dyn SourceProvider,
    errors: &mut Vec<Error>,
) {
    for segment in segments.iter_mut() {
        let Placed {
            fragments, bytes, ..
        } = segment;
        for fragment in fragments.iter() {
            let object = &objects[fragment.object];
            for field in object
                .fields
                .iter()
                .filter(|f| f.section == fragment.section)
            {
                let place = || object.place_of_byte(fragment.section, field.offset);
                let result = field.expr.evaluate(|index| {
                    values[fragment.object]
                        .get(index as usize)
                        .copied()
                        .flatten()
                });
                let value = match result {
                    Ok(value) => value,
                    Err(EvalError::UnresolvedSymbol(index))
                        if unresolved[fragment.object].get(index as usize) == Some(&true) =>
                    {
                        continue;
                    }
                    Err(error) => {
                        let place = place();
                        let (src, span) = place.snippet(sources);
                        errors.push(Error::ExpressionInvalid {
                            at: place.text,
                            reason: error.to_string(),
                            src,
                            span,
                        });
                        continue;
                    }
                };
                let Some(encoded) = field.kind.encode(value) else {
                    let place = place();
                    let (src, span) = place.snippet(sources);
                    errors.push(Error::ValueRange {
                        kind: "computed",
                        target: "of the expression".to_owned(),
                        value,
                        range: match field.kind {
                            FieldKind::Byte => "a byte (0 to 255)",
                            FieldKind::Word | FieldKind::WordBigEndian => "a word (0 to $FFFF)",
                            FieldKind::Far => "a far address (0 to $FFFFFF)",
                            FieldKind::Dword => "a dword (0 to $FFFFFFFF)",
                        },
                        at: place.text,
                        src,
                        span,
                    });
                    continue;
                };
                let start = (fragment.offset + u64::from(field.offset)) as usize;
                if let Some(target) = bytes.get_mut(start..start + encoded.len()) {
                    target.copy_from_slice(&encoded);
                }
            }
        }
    }
}

/// The `R_MOS_*` name of a relocation type, for messages.
fn relocation_name(r_type: u32) -> &'static str {
    isa::elf::relocation_name(r_type).unwrap_or("R_MOS_?")
}
