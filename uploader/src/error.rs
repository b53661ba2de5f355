//! The uploader's one error type.

use std::time::Duration;

use isa::objfmt::HookKind;
use romlib::protocol::ProtocolError;

/// Everything that can stop a probe, a read or an upload.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum Error {
    /// The robot's ROM is not the one the image was linked against: the
    /// image's calls into it would land elsewhere. Nothing was written.
    #[error(
        "the robot's ROM is not {profile}: {}",
        crate::fingerprint::describe(differences, *whole_sum)
    )]
    #[diagnostic(
        code(uploader::wrong_rom),
        help(
            "link the image against this robot's ROM (`scorpion rom read -o ROM.elf`, then `[robot] rom = \"ROM.elf\"` in the project's Scorpion.toml, or `scorpion link --just-symbols ROM.elf` outside a project), or use the robot it was built for"
        )
    )]
    WrongRom {
        /// The profile the image was linked against.
        profile: String,
        /// Bytes of the jump table and vectors that differ: address,
        /// expected, found.
        differences: Vec<(u16, u8, u8)>,
        /// The first range of the ROM whose checksum differs, expected
        /// and found, when the jump table agreed and the sums did not.
        whole_sum: Option<crate::fingerprint::RomSum>,
    },

    /// A range written through the loader kept summing otherwise on the
    /// robot than the image's bytes do.
    #[error(
        "${address:04X} and the {len} bytes from it still differ on the robot after {attempts} writes (a checksum computed on the robot)"
    )]
    #[diagnostic(
        code(uploader::sum_failed),
        help(
            "the line is very noisy or this memory does not hold what is written to it; `--full --loader never` writes and reads back each byte and names the first that will not hold"
        )
    )]
    SumFailed {
        /// The range's first address.
        address: u16,
        /// Its length.
        len: usize,
        /// Writes (or rounds) it took.
        attempts: u32,
    },

    /// A backup file that cannot be restored: nothing of it was written.
    #[error("{name} is not a backup this uploader can restore (at byte {offset}): {reason}")]
    #[diagnostic(
        code(uploader::bad_backup),
        help(
            "backups are written by `scorpion backup` and by every upload (for `scorpion upload --undo`); a damaged one is refused whole"
        )
    )]
    BadBackup {
        /// The file.
        name: String,
        /// Where in it.
        offset: usize,
        /// What is wrong.
        reason: String,
    },

    /// One of a project's images cannot go in beside what the robot
    /// holds or an image before it: refused before any is sent.
    #[error(
        "{image} cannot go in beside what the robot holds, or an image before it: nothing was sent to the robot (the project's images go in all or none)"
    )]
    #[diagnostic(
        code(uploader::image_in_the_way),
        help(
            "`--replace` takes out what the image overlaps on the robot; or move the image (its layout in the project), take out what is in the way (`scorpion upload --undo` of its upload), or reset the robot (/1R frees every entry)"
        )
    )]
    ImageInTheWay {
        /// The image's name.
        image: String,
        /// The overlap (its help, for an image outside a project, is not
        /// this one's: fresh25 F5).
        #[source]
        source: romlib::Error,
    },

    /// A project's images need more entries of the robot's table than it
    /// has free: refused before any is sent.
    #[error(
        "the project's images need {} in the robot's table of installed extensions, which has {free} free: nothing was sent to the robot (the project's images go in all or none)",
        romlib::installed::entries_text(.needed.to_owned())
    )]
    #[diagnostic(
        code(uploader::table_full),
        help(
            "`scorpion installed` lists what the robot holds; take some out (`scorpion upload --undo` goes back one upload), or reset the robot (/1R frees every entry)"
        )
    )]
    ProjectTableFull {
        /// Entries the images need.
        needed: usize,
        /// Entries free.
        free: usize,
    },

    /// The serial port is held by another program.
    #[error("serial port {port} is busy")]
    #[diagnostic(
        code(uploader::port_busy),
        help(
            "another program (a terminal, `scorpion sim`, a second upload) has it open; close it and retry"
        )
    )]
    PortBusy {
        /// The port's path.
        port: String,
    },

    /// The serial port does not exist.
    #[error("serial port {port} does not exist")]
    #[diagnostic(
        code(uploader::port_not_found),
        help("`scorpion ports` lists the serial ports of this machine")
    )]
    PortNotFound {
        /// The port's path.
        port: String,
    },

    /// The serial port could not be opened or configured.
    #[error("cannot open serial port {port}: {message}")]
    #[diagnostic(code(uploader::port))]
    Port {
        /// The port's path.
        port: String,
        /// What the operating system said.
        message: String,
    },

    /// Reading or writing the line failed (an unplugged adapter, a closed pty).
    #[error("I/O error on {port}")]
    #[diagnostic(code(uploader::io), help("check that the adapter is still plugged in"))]
    Io {
        /// The transport's name.
        port: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },

    /// The line's rate could not be changed.
    #[error("cannot set {port} to {baud} baud: {message}")]
    #[diagnostic(
        code(uploader::baud_change),
        help("the upload stays at the rate it connected at; --loader never avoids the switch")
    )]
    BaudChange {
        /// The transport's name.
        port: String,
        /// The rate asked for.
        baud: u32,
        /// Why not.
        message: String,
    },

    /// The robot answers only at the RAM loader's fast rate (an upload
    /// through the loader was interrupted there and a `/1R` unhooked it),
    /// and this upload does not use the loader, which alone brings the line
    /// back.
    #[error(
        "the robot on {port} answers at {found} baud, not {base}: an upload through the RAM loader was interrupted there"
    )]
    #[diagnostic(
        code(uploader::left_at_fast_rate),
        help(
            "press the robot's reset button (its 6551 goes back to the DIP switches' rate), or upload with --loader always: the loader's `/1F` brings the line back"
        )
    )]
    LeftAtFastRate {
        /// The transport's name.
        port: String,
        /// The rate the robot answers at.
        found: u32,
        /// The rate the upload was asked to run at.
        base: u32,
    },

    /// The virtual Scorpion's CPU executed a JAM opcode: the code it ran
    /// (an uploaded extension, most likely) is broken.
    #[error("the virtual Scorpion's CPU jammed at ${pc:04X} (opcode ${opcode:02X})")]
    #[diagnostic(
        code(uploader::robot_jammed),
        help("the image's code ran off into data; `scorpion emu` can trace it")
    )]
    RobotJammed {
        /// The address of the JAM opcode.
        pc: u16,
        /// The opcode.
        opcode: u8,
    },

    /// Nothing came back at all.
    #[error(
        "no answer from the robot on {port} at {baud} baud (`{question}` waited {})",
        human_duration(*.waited)
    )]
    #[diagnostic(
        code(uploader::no_answer),
        help(
            "check that the robot is on, the cable is a null-modem cable, the baud rate is the robot's (the reference ROM's is 9600), and the ROM is running (not an operating system that took HOOK_LOOP)"
        )
    )]
    NoAnswer {
        /// The transport's name.
        port: String,
        /// The baud rate used.
        baud: u32,
        /// The question that got no answer.
        question: String,
        /// How long it waited.
        waited: Duration,
    },

    /// What came back is the debug stub's stop frame (docs/PROTOCOL.md,
    /// section 5): a debug session that did not detach left the robot
    /// stopped at a breakpoint, and it reads no command.
    #[error(
        "the robot on {port} is stopped in the debug stub: a debug session left it at a breakpoint, and it reads no command"
    )]
    #[diagnostic(
        code(uploader::stopped_in_debug_stub),
        help(
            "`scorpion debug --port {port}` in the project that built the image it runs (elsewhere, with `--image ELF`) finds it stopped, takes the breakpoints and the stub out and lets it go on; or reset the robot"
        )
    )]
    StoppedInDebugStub {
        /// The transport's name.
        port: String,
    },

    /// A hook's way that reaches memory a replacement takes through code
    /// no entry of the table lists: the replacement could not re-point
    /// it (hostile25 F4, recheck25 R1).
    #[error(
        "{hook} leads {path}: into memory the image takes, through code no entry of the robot's table lists, which no upload can re-point; nothing was written"
    )]
    #[diagnostic(
        code(uploader::unlisted_way_in),
        help(
            "the robot's hooks or table were changed by hand (`scorpion installed` shows the chain): reset the robot (/1R frees every entry) or restore a backup from before, then upload again"
        )
    )]
    UnlistedWayIn {
        /// The hook.
        hook: &'static str,
        /// The way, `$0600 -> $0500`.
        path: String,
    },

    /// A hook's chain that comes back into the image: the image would
    /// chain to code that jumps back into it, a loop the robot would run
    /// for ever at its next unknown command.
    #[error(
        "{hook} leads {path}, back into the image: chained to it, the image would run in a loop the next time the robot follows {hook}; nothing was written"
    )]
    #[diagnostic(
        code(uploader::chain_comes_back),
        help(
            "the code on that way jumps into the memory the image takes (an earlier copy of it, an owner's JMP, a stub's chain, code whose table entry was freed): point {hook} back at the ROM (`scorpion restore` of a backup taken before, or reset the robot) and upload again; an image installed already, behind a handler of your own that jumps to it, needs no upload (`scorpion installed` lists it)"
        )
    )]
    ChainComesBack {
        /// The hook's name.
        hook: &'static str,
        /// The way, `$0600 -> $0400`.
        path: String,
    },

    /// The robot stopped answering once `HOOK_LOOP` was pointed at the
    /// image's handler: that handler does not come back to the ROM's
    /// loop, and the robot reads no command while it runs.
    #[error(
        "the robot stopped answering once HOOK_LOOP was pointed at the image's handler (${handler:04X}): {cause}"
    )]
    #[diagnostic(
        code(uploader::loop_handler_silent),
        help(
            "a HOOK_LOOP handler must end by going on to the ROM's loop (`SCORPION_CHAIN_LOOP`), every pass; while it does not, the robot reads no command. The image was verified before it was hooked; a robot left so is reset (its hooks go back to the ROM). `scorpion debug --image IMAGE` runs it on the virtual Scorpion, where Ctrl-C during `continue` shows where it loops"
        )
    )]
    LoopHandlerSilent {
        /// The image's `HOOK_LOOP` handler.
        handler: u16,
        /// What the line said.
        cause: Box<Error>,
    },

    /// An undo of an upload that is no longer the last on a hook: the
    /// hook leads first to code the undo file does not put back.
    #[error(
        "{hook} leads first to ${current:04X}{owner}, which this undo does not take out: an upload after the one it undoes, or a change by hand, put it there (chained ahead, or on a hook the undone upload left alone), and the undo would unhook that too; nothing was written"
    )]
    #[diagnostic(
        code(uploader::undo_not_last),
        help(
            "undo the later upload first: `scorpion upload --undo` where it was made (each undo goes back one upload, the last first), or `--undo-file FILE` with its undo file; where a `scorpion restore` put it back after its upload was undone (no undo file is left for it), restore a backup from before it instead; where you pointed the hook there by hand, point it back where it was (`scorpion installed` shows the hooks; PROTOCOL.md's `/9W`), undo, then point it at your code again"
        )
    )]
    UndoNotLast {
        /// The hook's name.
        hook: &'static str,
        /// Where it leads now.
        current: u16,
        /// ` (extension ID)` when the robot's table names it.
        owner: String,
    },

    /// The keeper could not keep what the upload was about to overwrite.
    #[error(
        "the undo file could not be written ({why}): the upload stopped before it changed the robot"
    )]
    #[diagnostic(
        code(uploader::undo_not_kept),
        help(
            "free space where it goes, or give `--undo-file FILE` in a directory that takes files"
        )
    )]
    UndoNotKept {
        /// Why.
        why: String,
    },

    /// An undo of an upload after which another upload wrote the table
    /// (a `--replace`, an extension added): the undo would put back the
    /// entries as they were before, over the later one's.
    #[error(
        "the robot's table lists extension {id:06X} (its entry at ${at:04X}), which an upload after the one this undoes wrote: the undo would put back what the entry held before, over it; nothing was written"
    )]
    #[diagnostic(
        code(uploader::undo_entry_changed),
        help(
            "undo the later upload first (`scorpion upload --undo` where it was made, or `--undo-file FILE` with its undo file), then this one"
        )
    )]
    UndoEntryChanged {
        /// The extension the table lists now.
        id: u32,
        /// Where its entry is.
        at: u16,
    },

    /// A restore whose hook would lead into code that loops, stops the
    /// CPU, or is the other hook's handler: the robot's hook was broken
    /// already when the file was written (`backup` warns of it), or the
    /// file was edited by hand.
    #[error(
        "the file points {hook} at ${target:04X}, and that way {why} ({path}): the memory was restored and verified, but {hook} is left at the ROM's target"
    )]
    #[diagnostic(
        code(uploader::restore_chain_broken),
        help(
            "the robot answers as it would with the extensions on that way not hooked; the robot's hook was broken already when the file was written (or the file was edited by hand): restore another, or upload those extensions again"
        )
    )]
    RestoreChainBroken {
        /// The hook's name.
        hook: &'static str,
        /// The file's target for it.
        target: u16,
        /// What is wrong with the way.
        why: &'static str,
        /// The way, `$0600 -> $0400`.
        path: String,
    },

    /// A backup whose `HOOK_UNKNOWN` leads to a debug stub it holds: taken
    /// while a debug session was attached, or after one died.
    #[error(
        "the backup points {hook} at a debug stub it holds (${stub:04X}-${end:04X}): it was taken while a debug session was attached, or after one died; restored, the stub would be back with no host, its breakpoints in the code; nothing was written"
    )]
    #[diagnostic(
        code(uploader::backup_holds_debug_stub),
        help(
            "restore a backup taken with no debug session attached (`scorpion debug --port PORT --image ELF`, then `quit`, takes a session's stub out before a backup)"
        )
    )]
    BackupHoldsDebugStub {
        /// The hook's name.
        hook: &'static str,
        /// Where the stub starts.
        stub: u16,
        /// Its last byte, data included.
        end: u16,
    },

    /// A debug stub a session left hooked (its process killed before it
    /// detached): chaining to it would loop back to the image it debugged,
    /// and its breakpoints may still be in the code.
    #[error(
        "{hook} on {port} leads to a debug stub at ${stub:04X}-${end:04X} (chaining to ${previous:04X}): a debug session did not detach, and its breakpoints may still be in the code; nothing was written"
    )]
    #[diagnostic(
        code(uploader::debug_stub_hooked),
        help(
            "`scorpion debug --port {port}` in the project that built the image it debugged (elsewhere, with `--image ELF`) takes the stub and its breakpoints out: run it, `quit`, and try again; or reset the robot"
        )
    )]
    DebugStubHooked {
        /// The transport's name.
        port: String,
        /// The hook's name.
        hook: &'static str,
        /// Where the stub starts.
        stub: u16,
        /// Its code's last byte.
        end: u16,
        /// What it chains to.
        previous: u16,
    },

    /// Bytes came back, but never a well-formed answer: the usual sign of a
    /// baud-rate mismatch.
    #[error("the robot on {port} answers garbage at {baud} baud: `{sample}`")]
    #[diagnostic(
        code(uploader::wrong_baud),
        help(
            "the robot is probably set to another baud rate; try --baud 9600 (the ROM's default)"
        )
    )]
    WrongBaud {
        /// The transport's name.
        port: String,
        /// The baud rate used.
        baud: u32,
        /// What arrived, escaped.
        sample: String,
    },

    /// The line went quiet in the middle of the work.
    #[error(
        "the line to {port} stalled: nothing received for {} with {} due",
        human_duration(*.waited),
        if *.outstanding == 1 { "an answer".to_owned() } else { format!("{} answers", .outstanding) }
    )]
    #[diagnostic(
        code(uploader::stalled),
        help(
            "the robot stopped answering (power, cable, or a crash); nothing that did not verify was hooked, so the command is safe to run again"
        )
    )]
    Stalled {
        /// The transport's name.
        port: String,
        /// How long nothing arrived.
        waited: Duration,
        /// Questions still unanswered.
        outstanding: usize,
    },

    /// A byte never read back as written.
    #[error(
        "verification failed at ${address:04X}: expected ${expected:02X}, found ${found:02X} after {attempts} writes"
    )]
    #[diagnostic(
        code(uploader::verify_failed),
        help(
            "that address does not keep what is written: no RAM there (check the image's layout) or a faulty line; no hook was installed"
        )
    )]
    VerifyFailed {
        /// The address.
        address: u16,
        /// The image's byte.
        expected: u8,
        /// The robot's byte.
        found: u8,
        /// How many times it was written.
        attempts: u32,
    },

    /// The robot's ROM is not the one a backup was taken from: the RAM it
    /// holds calls into that ROM. Nothing was changed.
    #[error(
        "the robot's ROM is not the one the backup was taken from: {}",
        crate::fingerprint::describe(differences, None)
    )]
    #[diagnostic(
        code(uploader::backup_rom_differs),
        help(
            "restore it onto the robot it was taken from; `scorpion restore FILE --force` restores it anyway (its code's calls into the ROM may land elsewhere)"
        )
    )]
    BackupRomDiffers {
        /// Bytes of the jump table and vectors that differ: address, in
        /// the backup, on the robot.
        differences: Vec<(u16, u8, u8)>,
    },

    /// Memory a restored hook would point into no longer holds what it
    /// held when the backup was written. Nothing was changed.
    #[error(
        "${address:04X}-${end:04X}, {what}, is not what it was when the backup was written: its checksum was {expected}, the robot's is {found}; nothing was changed",
        end = u32::from(*address) + u32::from(*len) - 1
    )]
    #[diagnostic(
        code(uploader::witness_differs),
        help(
            "the hook would point at code that is not there: this is another robot, or a restore, an upload or a change by hand has changed it since (memory a backup does not save, the KIM bus's, is only witnessed); put that code back as it was, take a new backup, or upload the image again instead (`--force` overrides only a ROM that differs)"
        )
    )]
    WitnessDiffers {
        /// What the memory is: the table of installed extensions' entry
        /// of the hooked extension, or the code a hook goes back to.
        what: &'static str,
        /// The first address.
        address: u16,
        /// How many bytes.
        len: u16,
        /// The sum in the backup.
        expected: crate::backup::Checksum,
        /// The robot's.
        found: crate::backup::Checksum,
    },

    /// A backup's hook leads on, by a chain slot or a `JMP` the file
    /// holds, into RAM the file neither restores nor witnesses (hostile26
    /// F1). Nothing was written.
    #[error(
        "the file's {hook} leads {path} and runs the code at ${target:04X}, which the file neither restores (it holds no byte there) nor witnesses (no checksum of it covers it): the code there is not checked, and the robot would run whatever that memory holds; nothing was written"
    )]
    #[diagnostic(
        code(uploader::unwitnessed_hook),
        help(
            "a file `scorpion backup` writes holds user RAM and witnesses every byte of code each hook's way runs outside it: this file was made by an older `scorpion backup`, or changed by something else, or that code changed while `backup` read it; take a new backup, restore another, or upload the extensions instead"
        )
    )]
    UnwitnessedStep {
        /// The hook.
        hook: &'static str,
        /// Where the way goes that nothing checks.
        target: u16,
        /// The way there, `$0803 -> $0503`.
        path: String,
    },

    /// An undo file's hook leads on, past the code it witnesses, into RAM
    /// it neither puts back nor witnesses and that no entry of the robot's
    /// table lists now (hostile26 F1b). Nothing was written.
    #[error(
        "the undo file's {hook} leads {path} and runs the code at ${target:04X}, which the file neither puts back nor witnesses, no entry of the robot's table lists now, and no hook of the robot leads through now: the code there is not checked, and the robot would run whatever that memory holds; nothing was written"
    )]
    #[diagnostic(
        code(uploader::undo_step_unlisted),
        help(
            "an undo file holds what its upload overwrote and witnesses the code its hooks go back to; what lies further on must be an extension the robot still lists, or code its hooks run now. A reset (`/1R`) clears the table, and a file changed by hand may point anywhere: upload the extensions again, or restore a backup taken with `scorpion backup`"
        )
    )]
    UndoStepUnlisted {
        /// The hook.
        hook: &'static str,
        /// Where the way goes that nothing checks.
        target: u16,
        /// The way there, `$0803 -> $0503`.
        path: String,
    },

    /// An undo file puts in code no entry of its table lists, on a hook's
    /// way, where no hook of the robot runs code now (hostile28 F5: a
    /// record added by hand, a hook pointed at it). Nothing was written.
    #[error(
        "the undo file's {hook} leads {path} and runs the code it puts in at ${target:04X}, which no entry of the table lists and no hook of the robot runs now: an upload's undo puts back such code only where the upload found a hook running it, and overwrote none of it; nothing was written"
    )]
    #[diagnostic(
        code(uploader::undo_adds_code),
        help(
            "this undo file was changed by hand, or the robot's hooks were moved since the upload: upload the extension you want as an image (it is then listed and checked), or restore a backup taken with `scorpion backup`"
        )
    )]
    UndoAddsCode {
        /// The hook.
        hook: &'static str,
        /// The first byte of that code the way runs.
        target: u16,
        /// The way there, `$0803 -> $0503`.
        path: String,
    },

    /// A backup's hook leads through code that jumps where its data says,
    /// part of it outside what the file restores (hostile29 F1). Nothing
    /// was written.
    #[error(
        "the file's {hook} leads {path}, and at ${at:04X} jumps where its data says (through a pointer, or an RTS to an address it pushed), while part of that way's code lies outside what the file restores (${outside:04X}, only witnessed): the code it may jump to cannot all be known, so a restore cannot check it; nothing was written"
    )]
    #[diagnostic(
        code(uploader::computed_way_outside),
        help(
            "`scorpion backup` witnesses the code a way was seen to run; a jump table's other targets on the KIM bus may have changed unseen. Keep such code in user RAM, where a backup holds it all, or upload it as an extension (its image is checked as it goes in)"
        )
    )]
    ComputedWayOutside {
        /// The hook.
        hook: &'static str,
        /// The way, `$0716 -> $1000`.
        path: String,
        /// The computed jump.
        at: u16,
        /// The first byte of the way's code outside what the file holds.
        outside: u16,
    },

    /// An undo would list again an extension the robot no longer lists,
    /// from what memory still holds, where the file checks part of it
    /// only (hostile28 F6, F7: a reset since). Nothing was written.
    #[error(
        "the undo would list {extension} again, which the robot no longer lists (nor any extension the undo takes out: a reset since the upload clears the table), and the file neither puts back nor witnesses {what}: what memory holds there may have changed since; nothing was written"
    )]
    #[diagnostic(
        code(uploader::undo_relists_unchecked),
        help(
            "a reset (`/1R`) clears the table and leaves memory for anyone to change, so no undo file kept before it can be used: upload the extensions you want again (each image is checked as it goes in), or restore a backup taken with `scorpion backup`"
        )
    )]
    UndoRelistsUnchecked {
        /// The extension, as `installed` names it.
        extension: String,
        /// What of it nothing checks, with the first such address.
        what: String,
    },

    /// A backup or undo file points a hook into RAM that it neither
    /// restores nor witnesses: nothing tells what code is there, and the
    /// robot would jump into whatever it holds. Nothing was written.
    #[error(
        "the file points {hook} at ${target:04X}, which is not in the ROM's code, not restored by this file (it holds no byte there) and not witnessed by it (no checksum of the file covers it): the robot would jump into whatever that memory holds; nothing was written"
    )]
    #[diagnostic(
        code(uploader::unwitnessed_hook),
        help(
            "a file `scorpion backup` writes holds the memory each hook goes to, and an upload's undo file holds or witnesses the code each kept hook goes back to: this file was made or changed by something else; restore another backup, or upload the image instead"
        )
    )]
    UnwitnessedHook {
        /// The hook (`HOOK_UNKNOWN`, `HOOK_LOOP`).
        hook: &'static str,
        /// Where the file points it.
        target: u16,
    },

    /// Reads of the same bytes kept answering differently, well formed:
    /// memory the robot writes while it runs, not a noisy line.
    #[error(
        "the bytes at {} changed between reads of ${address:04X}-${last:04X}: this memory is in use (the robot writes it while it runs), not a noisy line",
        crate::error::addresses_text(changed)
    )]
    #[diagnostic(
        code(uploader::memory_changing),
        help(
            "read memory the robot does not write while it runs (its zero page, receive buffer and stack change with every command); the reads stop after two answers agree"
        )
    )]
    MemoryChanging {
        /// The first address of the read.
        address: u16,
        /// Its last address.
        last: u16,
        /// The addresses whose bytes changed between well-formed answers.
        changed: Vec<u16>,
    },

    /// The answers kept being malformed or lost.
    #[error("gave up reading ${address:04X} after {attempts} garbled or lost answers")]
    #[diagnostic(
        code(uploader::unreadable),
        help("the line is too noisy; try a lower baud rate or a shorter cable")
    )]
    Unreadable {
        /// The first address of the read.
        address: u16,
        /// Attempts made.
        attempts: u32,
        /// The last malformed answer, if one was parsed.
        #[source]
        last: Option<ProtocolError>,
    },

    /// The robot reset (or something else rewrote its hooks) while the
    /// upload was installing hooks, more often than the retries allow.
    #[error("the robot reset during the upload: {hook} changed from ${before:04X} to ${after:04X}")]
    #[diagnostic(
        code(uploader::robot_reset),
        help(
            "the robot reset or another program wrote to it; nothing of the image is hooked; upload again (a reset frees every installed extension: `scorpion installed` lists what is left)"
        )
    )]
    RobotReset {
        /// The hook that changed.
        hook: &'static str,
        /// Its target when the upload began.
        before: u16,
        /// Its target now.
        after: u16,
    },

    /// A hook's RAM does not hold a `JMP`: not a ROM this uploader knows.
    #[error("{hook} at ${address:04X} holds ${found:02X}, not a JMP ($4C)")]
    #[diagnostic(
        code(uploader::not_a_hook),
        help("the robot's ROM is not the one the image was linked against; pass its ROM profile")
    )]
    NotAHook {
        /// The hook's name.
        hook: &'static str,
        /// Its address.
        address: u16,
        /// The byte found where the `JMP` should be.
        found: u8,
    },

    /// A hook currently points into memory the upload is about to
    /// overwrite, and no ROM default is known to disarm it with.
    #[error("{hook} points at ${target:04X}, inside the memory being uploaded")]
    #[diagnostic(
        code(uploader::hook_in_use),
        help(
            "an earlier upload is hooked there; send /1R to the robot (it restores the hooks), then upload again"
        )
    )]
    HookInUse {
        /// The hook's name.
        hook: &'static str,
        /// Where it points.
        target: u16,
    },

    /// What a backup or undo file would write is not something a backup
    /// or an upload wrote (a file made or changed by hand): refused before
    /// anything is written.
    #[error("{reason}")]
    #[diagnostic(
        code(uploader::backup_refused),
        help(
            "backups and undo files are written by `scorpion backup` and by every upload; this one was made or changed by hand, or damaged, or is a backup of a robot changed by hand (`scorpion backup` warned of it as it saved): restore another, or reset the robot (/1R) and upload the extensions again"
        )
    )]
    BackupRefused {
        /// What the file would do, and why it is refused.
        reason: String,
    },

    /// The image is not something that can be uploaded safely.
    #[error("the image cannot be uploaded: {reason}")]
    #[diagnostic(
        code(uploader::bad_image),
        help("link extensions with --target scorpion-ext (or scorpion-os)")
    )]
    BadImage {
        /// Why.
        reason: String,
    },

    /// A ROM profile lacks what the uploader needs.
    #[error("ROM profile {name} cannot be used: {reason}")]
    #[diagnostic(
        code(uploader::bad_rom_profile),
        help(
            "give the linked ELF of the robot's ROM, which exports the names of docs/PROTOCOL.md section 4"
        )
    )]
    BadRomProfile {
        /// The profile's name.
        name: String,
        /// Why.
        reason: String,
    },

    /// `--loader always`, but the RAM loader cannot be used for this upload.
    #[error("the RAM loader cannot be used: {reason}")]
    #[diagnostic(
        code(uploader::loader_unavailable),
        help("--loader auto uses it only where it can, --loader never never")
    )]
    LoaderUnavailable {
        /// Why.
        reason: String,
    },

    /// The RAM loader could not be linked (a ROM profile without the
    /// services it calls, or no room).
    #[error("cannot link the RAM loader at ${address:04X}: {message}")]
    #[diagnostic(code(uploader::loader_link))]
    LoaderLink {
        /// Where it was to go.
        address: u16,
        /// The linker's complaint.
        message: String,
    },

    /// A chain slot or handler of a hook record lies outside the image.
    #[error("{kind:?} hook record names ${address:04X}, which the image does not load")]
    #[diagnostic(code(uploader::bad_hook_record))]
    BadHookRecord {
        /// Which hook.
        kind: HookKind,
        /// The address.
        address: u16,
    },

    /// A protocol error outside the retried paths (a probe's answer, say).
    #[error(transparent)]
    #[diagnostic(transparent)]
    Protocol(#[from] ProtocolError),

    /// What the robot's own state refuses: an image that overlaps an
    /// installed extension, a full or damaged table of installed ones.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Robot(#[from] romlib::Error),

    /// The expectation file's commands did not get the answers it requires.
    #[error("rehearsal failed: `{command}` answered `{found}`, expected `{expected}`")]
    #[diagnostic(
        code(uploader::rehearsal_failed),
        help(
            "the image does not behave on the virtual Scorpion as the expectations say; nothing was sent to the robot"
        )
    )]
    RehearsalFailed {
        /// The command.
        command: String,
        /// The required answer.
        expected: String,
        /// The actual answer (or `no answer`).
        found: String,
    },

    /// The expectation file does not parse.
    #[error("expectations line {line}: {reason}")]
    #[diagnostic(
        code(uploader::bad_expectations),
        help("each line is `COMMAND` or `COMMAND => ANSWER`; `#` starts a comment")
    )]
    BadExpectations {
        /// 1-based line.
        line: usize,
        /// Why.
        reason: String,
    },
}

/// The uploader's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A duration as people read it: `3.6 s`, `250 ms`, `12 µs`, three
/// significant figures at most.
#[must_use]
pub fn human_duration(duration: Duration) -> String {
    let seconds = duration.as_secs_f64();
    let (value, unit) = if seconds >= 1.0 {
        (seconds, "s")
    } else if seconds >= 1e-3 {
        (seconds * 1e3, "ms")
    } else {
        (seconds * 1e6, "µs")
    };
    let text = if value >= 100.0 {
        format!("{value:.0}")
    } else if value >= 10.0 {
        format!("{value:.1}")
    } else {
        format!("{value:.2}")
    };
    let text = match text.contains('.') {
        true => text.trim_end_matches('0').trim_end_matches('.').to_string(),
        false => text,
    };
    format!("{text} {unit}")
}

/// `$00F0, $00F1 and 3 more`: the first addresses of a list, for messages.
/// `$0422, $0423` and so on: the first few of `addresses`, and how many
/// more.
#[must_use]
pub fn addresses_text(addresses: &[u16]) -> String {
    const SHOWN: usize = 8;
    let mut text = addresses
        .iter()
        .take(SHOWN)
        .map(|address| format!("${address:04X}"))
        .collect::<Vec<_>>()
        .join(", ");
    if addresses.len() > SHOWN {
        text.push_str(&format!(" and {} more", addresses.len() - SHOWN));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::human_duration;
    use std::time::Duration;

    #[test]
    fn durations_read_as_people_write_them() {
        assert_eq!(
            human_duration(Duration::from_secs_f64(3.614_583_33)),
            "3.61 s"
        );
        assert_eq!(human_duration(Duration::from_millis(250)), "250 ms");
        assert_eq!(human_duration(Duration::from_millis(1500)), "1.5 s");
        assert_eq!(human_duration(Duration::from_secs(120)), "120 s");
        assert_eq!(human_duration(Duration::from_micros(12)), "12 µs");
        assert_eq!(human_duration(Duration::from_micros(10_400)), "10.4 ms");
        assert_eq!(human_duration(Duration::ZERO), "0 µs");
    }
}
