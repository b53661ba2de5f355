//! The name interner: every identifier and directive becomes a [`NameId`]
//! once, so the hot paths compare integers, and each name carries what it
//! means to the assembler (mnemonic, directive, register) from the moment
//! it is first seen.

use std::rc::Rc;

use isa::Mnemonic;
use rustc_hash::FxHashMap;

/// An interned name.
pub(crate) type NameId = u32;

macro_rules! directives {
    ($( $variant:ident = $($name:literal)|+ ;)*) => {
        /// A directive or pseudo-function (`.byte`, `.lobyte`...);
        /// `NoEffect` gathers ca65's listing and debug-info switches.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub(crate) enum Dir { $( $variant, )* }

        /// Every directive name and alias, without the dot (for "did you
        /// mean" suggestions).
        pub(crate) const DIRECTIVE_NAMES: &[&str] = &[ $( $($name,)+ )* ];

        fn directive(lower: &str) -> Option<Dir> {
            match lower {
                $( $($name)|+ => Some(Dir::$variant), )*
                _ => None,
            }
        }
    };
}

directives! {
    Addr = "addr";
    Align = "align";
    And = "and";
    Asciiz = "asciiz";
    Assert = "assert";
    Bankbyte = "bankbyte";
    Bankbytes = "bankbytes";
    Bitand = "bitand";
    Bitnot = "bitnot";
    Bitor = "bitor";
    Bitxor = "bitxor";
    Autoimport = "autoimport";
    Blank = "blank";
    Bss = "bss";
    Byte = "byte" | "byt";
    Charmap = "charmap";
    Code = "code";
    Case = "case";
    Const = "const";
    Data = "data";
    Dbyt = "dbyt";
    Define = "define";
    Defined = "defined" | "def";
    Dword = "dword";
    Else = "else";
    Elseif = "elseif";
    Endenum = "endenum";
    End = "end";
    Endif = "endif";
    Endmacro = "endmacro" | "endmac";
    Endproc = "endproc";
    Endrepeat = "endrepeat" | "endrep";
    Endscope = "endscope";
    Endstruct = "endstruct";
    Endunion = "endunion";
    Enum = "enum";
    Error = "error";
    Exitmacro = "exitmacro" | "exitmac";
    Export = "export";
    Exportzp = "exportzp";
    Fatal = "fatal";
    Feature = "feature";
    Global = "global";
    NoEffect = "debuginfo" | "dbg" | "smart" | "listbytes" | "pagelength" | "fopt" | "fileopt";
    Globalzp = "globalzp";
    Hibyte = "hibyte";
    Hibytes = "hibytes";
    Hiword = "hiword";
    If = "if";
    Ifblank = "ifblank";
    Ifconst = "ifconst";
    Ifdef = "ifdef";
    Ifnblank = "ifnblank";
    Ifndef = "ifndef";
    Ifnref = "ifnref";
    Ifp02 = "ifp02";
    Ifp816 = "ifp816";
    Ifpc02 = "ifpc02";
    Ifref = "ifref";
    Faraddr = "faraddr";
    Condes = "condes";
    Constructor = "constructor";
    Destructor = "destructor";
    Interruptor = "interruptor";
    Forceimport = "forceimport";
    Import = "import";
    Importzp = "importzp";
    Incbin = "incbin";
    Include = "include";
    List = "list";
    Local = "local";
    Lobyte = "lobyte";
    Lobytes = "lobytes";
    Loword = "loword";
    Macro = "macro" | "mac";
    Macpack = "macpack";
    Mod = "mod";
    Not = "not";
    Or = "or";
    Org = "org";
    Out = "out";
    P02 = "p02";
    OtherCpu = "p816" | "pc02" | "psc02" | "p4510";
    Paramcount = "paramcount";
    Pushseg = "pushseg";
    Popseg = "popseg";
    Pushcpu = "pushcpu";
    Popcpu = "popcpu";
    Cpu = "cpu";
    Left = "left";
    Mid = "mid";
    Right = "right";
    Concat = "concat";
    String = "string";
    Ident = "ident";
    Sprintf = "sprintf";
    Tcount = "tcount";
    Addrsize = "addrsize";
    Version = "version";
    Linecont = "linecont";
    Match = "match";
    Xmatch = "xmatch";
    Proc = "proc";
    Referenced = "referenced" | "ref";
    Reloc = "reloc";
    Repeat = "repeat";
    Res = "res";
    Rodata = "rodata";
    Scope = "scope";
    Segment = "segment";
    Set = "set";
    Setcpu = "setcpu";
    Shl = "shl";
    Shr = "shr";
    Sizeof = "sizeof";
    Strat = "strat";
    Strlen = "strlen";
    Struct = "struct";
    Tag = "tag";
    Undefine = "undefine" | "undef";
    Union = "union";
    Warning = "warning";
    Word = "word";
    Xor = "xor";
    Zeropage = "zeropage";
}

impl Dir {
    /// `.if` and its relatives: the directives that open a conditional.
    pub(crate) fn opens_conditional(self) -> bool {
        matches!(
            self,
            Dir::If
                | Dir::Ifdef
                | Dir::Ifndef
                | Dir::Ifblank
                | Dir::Ifnblank
                | Dir::Ifconst
                | Dir::Ifref
                | Dir::Ifnref
                | Dir::Ifp02
                | Dir::Ifpc02
                | Dir::Ifp816
        )
    }
}

/// What a name means before any symbol is looked up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Keyword {
    /// An ordinary identifier.
    None,
    /// An instruction mnemonic (any case).
    Mnemonic(Mnemonic),
    /// A directive (the name starts with `.`).
    Directive(Dir),
    /// `a` / `A`: the accumulator, or the `a:` address-size prefix.
    RegA,
    /// `x` / `X`.
    RegX,
    /// `y` / `Y`.
    RegY,
    /// `z:` zero-page address-size prefix.
    SizeZ,
    /// `f:` far (24-bit) address-size prefix, refused on the 6502.
    SizeF,
}

/// Per-name data the front end needs on every line.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NameInfo {
    /// The fixed meaning.
    pub(crate) keyword: Keyword,
    /// The macro of that name, if one is defined.
    pub(crate) macro_id: Option<u32>,
    /// The `.define` of that name, if one is active.
    pub(crate) define_id: Option<u32>,
}

/// The interner.
#[derive(Debug, Default)]
pub(crate) struct Interner {
    /// Names of up to 16 bytes (nearly all), held in the table itself: a
    /// lookup compares in the bucket instead of following a pointer to the
    /// name, which in a large program is a cache miss per identifier.
    short: FxHashMap<[u64; 2], NameId>,
    /// Longer names, and any containing a NUL byte (the padding of `short`).
    long: FxHashMap<Rc<[u8]>, NameId>,
    names: Vec<Rc<str>>,
    pub(crate) info: Vec<NameInfo>,
}

/// `bytes` zero-padded to 16, when that is unambiguous.
fn short_key(bytes: &[u8]) -> Option<[u64; 2]> {
    if bytes.len() > 16 || bytes.contains(&0) {
        return None;
    }
    let mut padded = [0u8; 16];
    padded[..bytes.len()].copy_from_slice(bytes);
    let (low, high) = padded.split_at(8);
    Some([
        u64::from_le_bytes(low.try_into().ok()?),
        u64::from_le_bytes(high.try_into().ok()?),
    ])
}

impl Interner {
    pub(crate) fn new() -> Interner {
        Interner::default()
    }

    /// The id of `name`, interning it on first sight.
    pub(crate) fn intern(&mut self, name: &str) -> NameId {
        self.intern_bytes(name.as_bytes())
    }

    /// Interns a name given as bytes; the lexer passes ASCII identifier
    /// bytes and this avoids re-validating them as UTF-8 on every lookup.
    pub(crate) fn intern_bytes(&mut self, bytes: &[u8]) -> NameId {
        let short = short_key(bytes);
        let found = match short {
            Some(key) => self.short.get(&key),
            None => self.long.get(bytes),
        };
        if let Some(id) = found {
            return *id;
        }
        let name = String::from_utf8_lossy(bytes);
        let id = self.names.len() as NameId;
        let rc: Rc<str> = Rc::from(name.as_ref());
        match short {
            Some(key) => self.short.insert(key, id),
            None => self.long.insert(Rc::from(bytes), id),
        };
        self.names.push(Rc::clone(&rc));
        self.info.push(NameInfo {
            keyword: keyword_of(&rc),
            macro_id: None,
            define_id: None,
        });
        id
    }

    pub(crate) fn name(&self, id: NameId) -> &str {
        self.names.get(id as usize).map_or("", |n| n)
    }

    pub(crate) fn keyword(&self, id: NameId) -> Keyword {
        self.info
            .get(id as usize)
            .map_or(Keyword::None, |info| info.keyword)
    }

    pub(crate) fn info_mut(&mut self, id: NameId) -> Option<&mut NameInfo> {
        self.info.get_mut(id as usize)
    }
}

fn keyword_of(name: &str) -> Keyword {
    if name.len() > 16 {
        return Keyword::None;
    }
    let lower = name.to_ascii_lowercase();
    if let Some(rest) = lower.strip_prefix('.') {
        return directive(rest).map_or(Keyword::None, Keyword::Directive);
    }
    match lower.as_str() {
        "a" => return Keyword::RegA,
        "x" => return Keyword::RegX,
        "y" => return Keyword::RegY,
        "z" => return Keyword::SizeZ,
        "f" => return Keyword::SizeF,
        _ => {}
    }
    Mnemonic::from_name(&lower).map_or(Keyword::None, Keyword::Mnemonic)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keywords_ignore_case_but_names_do_not() {
        let mut names = Interner::new();
        let lower = names.intern("lda");
        let upper = names.intern("LDA");
        assert_ne!(lower, upper);
        assert_eq!(names.keyword(lower), Keyword::Mnemonic(Mnemonic::Lda));
        assert_eq!(names.keyword(upper), Keyword::Mnemonic(Mnemonic::Lda));
        let byte = names.intern(".BYT");
        assert_eq!(names.keyword(byte), Keyword::Directive(Dir::Byte));
        let label = names.intern("label");
        assert_eq!(names.keyword(label), Keyword::None);
        assert_eq!(names.intern("lda"), lower);
        assert_eq!(names.name(upper), "LDA");
    }

    #[test]
    fn short_long_and_padded_names_stay_apart() {
        let mut names = Interner::new();
        let sixteen = names.intern("abcdefghijklmnop");
        let seventeen = names.intern("abcdefghijklmnopq");
        let nul = names.intern("a\0");
        let a = names.intern("a");
        assert_eq!(
            [sixteen, seventeen, nul, a],
            [0, 1, 2, 3],
            "four different names"
        );
        assert_eq!(names.intern("abcdefghijklmnopq"), seventeen);
        assert_eq!(names.intern("a\0"), nul);
        assert_eq!(names.intern("abcdefghijklmnop"), sixteen);
        assert_eq!(names.name(nul), "a\0");
        assert_eq!(names.intern_bytes(b""), names.intern(""));
    }
}
