//! Progress reporting: a trait with no-op defaults, implemented by the CLI
//! (a progress bar) and ignored by tests.

use isa::objfmt::HookKind;
use romlib::protocol::ProtocolError;

/// A stage of an upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Probing the robot and reading its hooks.
    Connect,
    /// Writing the body with overlapping verification reads.
    Write,
    /// A read-only pass over every byte, after faults were seen.
    FinalVerify,
    /// Installing the RAM loader.
    Loader,
    /// Installing the hooks.
    Hooks,
}

/// Something worth telling the user about, none of them fatal.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Event {
    /// Bytes read back wrong and were written again.
    Rewrite {
        /// The first address rewritten.
        address: u16,
        /// How many bytes.
        count: usize,
    },
    /// An answer never came (or came too late) and the question was asked again.
    LostAnswer {
        /// The first address of the read.
        address: u16,
    },
    /// An answer was malformed and the question was asked again.
    MalformedAnswer(ProtocolError),
    /// A hook changed on the robot during the upload (a reset?).
    HookChanged {
        /// Which hook.
        kind: HookKind,
        /// Its target when the upload began.
        before: u16,
        /// Its target now.
        after: u16,
    },
    /// A hook that pointed into the memory being written was reset to the
    /// ROM's own target first.
    HookDisarmed {
        /// Which hook.
        kind: HookKind,
        /// Where it pointed.
        from: u16,
        /// Where it points now.
        to: u16,
    },
    /// A way out the robot's chain held was no way for a command to go
    /// (a hook or chain slot damaged by hand): the image falls through to
    /// the ROM's target instead.
    WayOutDropped {
        /// Which hook.
        kind: HookKind,
        /// Where the way out led.
        from: u16,
        /// Where it was read, where that was not the hook itself: the
        /// chain slot of what the hook led to inside the upload (an
        /// earlier copy of the image, or code by hand there: recheck27 P2).
        slot: Option<u16>,
        /// Why it is no way.
        why: &'static str,
        /// The way followed.
        path: String,
    },
    /// A hook now points at verified code.
    HookInstalled {
        /// Which hook.
        kind: HookKind,
        /// The handler.
        handler: u16,
        /// The previous target, now the extension's fallthrough.
        previous: u16,
    },
    /// The RAM loader took over the transfer.
    LoaderInstalled {
        /// Where it runs.
        address: u16,
        /// Its size in bytes.
        len: usize,
        /// The rate the transfer runs at.
        baud: u32,
    },
    /// The RAM loader was found unhooked or the line at the wrong rate
    /// (a reset), and was restored.
    LoaderRestored {
        /// Where `HOOK_UNKNOWN` pointed, when it could be read.
        hook: Option<u16>,
        /// The rate the robot answered at.
        baud: u32,
    },
    /// The RAM loader was removed.
    LoaderRemoved,
    /// A ROM check refused, and the caller's `force_rom` overrode it (a
    /// restore with `--force`): what it found.
    RomCheckOverridden {
        /// The refusal the check gave.
        refusal: String,
    },
    /// A restore's checks passed: it writes from here on. One stopped
    /// after this may be run again with [`crate::UploadOptions::resume`].
    RestoreStarted,
    /// Once a restore is done: an extension the robot's table lists on a
    /// hook whose chain does not lead to it (listed, and never run, as
    /// the file had it; `installed` marks it "not hooked").
    RestoredNotHooked {
        /// The disagreement.
        found: crate::held_way::Disagreement,
    },
}

/// Receives progress; every method has a no-op default.
pub trait Progress {
    /// A phase begins; `total` is the bytes it will cover.
    fn phase(&mut self, _phase: Phase, _total: usize) {}
    /// `done` bytes of the phase are verified.
    fn advanced(&mut self, _done: usize) {}
    /// Something happened.
    fn event(&mut self, _event: &Event) {}
}

/// Ignores all progress.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {}

impl<P: Progress + ?Sized> Progress for &mut P {
    fn phase(&mut self, phase: Phase, total: usize) {
        (**self).phase(phase, total);
    }
    fn advanced(&mut self, done: usize) {
        (**self).advanced(done);
    }
    fn event(&mut self, event: &Event) {
        (**self).event(event);
    }
}
