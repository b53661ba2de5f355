//! The shadow call stack and the call tree.
//!
//! A routine is what a `JSR` enters; it is left by the `RTS` that brings
//! the stack pointer back to where it was before the `JSR` (so an `RTS`
//! used as a jump, after pushing an address, leaves nothing). An IRQ, an
//! NMI or a `BRK` starts a frame that is the root of a tree of its own,
//! not a child of whatever it interrupted, and its `RTI` ends it. A robot
//! command is a frame too, under the control loop, from its arrival to the
//! ROM's `CMD_DONE`: a handler is entered by a jump, not a call, and the
//! command frame is where its cycles show in the flame graph. `TXS` (a
//! reset) unwinds the frames it leaves above the stack pointer.
//!
//! Every frame is a node of the call tree (its routine under its parent's
//! node); the cycles of each instruction go to a cell: the node it ran in
//! and the label of its address, so a flame graph shows the label a
//! routine's cycles were spent at as its top box.

use rustc_hash::FxHashMap;

use crate::engine::Labels;

/// What a frame stands for.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Routine {
    /// The control loop and everything not inside a call: the root.
    Main,
    /// An IRQ handler.
    Irq,
    /// An NMI handler.
    Nmi,
    /// A `BRK` handler.
    Brk,
    /// The routine a `JSR` entered, by its address.
    Sub(u16),
    /// A robot command from its arrival to `CMD_DONE` (`/2A1`).
    Command(String),
}

/// How a frame ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ends {
    /// At an `RTS` (or `TXS`) that raises S to `return_s` or above.
    Return { return_s: u8 },
    /// At an `RTI` that raises S to `return_s` or above.
    Interrupt { return_s: u8 },
    /// When the command is done.
    Command,
}

#[derive(Debug, Clone, Copy)]
struct Frame {
    node: u32,
    routine: u32,
    /// The cycle the frame began at.
    entry: u64,
    ends: Ends,
    /// How many runs it stands for (the laps of a skipped idle loop).
    times: u64,
}

/// What the calls of one routine cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Calls {
    /// Times entered.
    pub(crate) calls: u64,
    /// Calls that ended (the rest were still running at the end).
    pub(crate) ended: u64,
    /// Cycles from entry to exit, over every call that ended.
    pub(crate) inclusive: u64,
    /// The cheapest call that ended.
    pub(crate) min: u64,
    /// The dearest call that ended.
    pub(crate) max: u64,
    /// The call tree node of the dearest call.
    pub(crate) worst_node: u32,
    /// The command running during the dearest call (an index into the
    /// commands seen), if any.
    pub(crate) worst_command: Option<u32>,
}

/// A call tree node: a routine under its parent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Node {
    pub(crate) parent: u32,
    pub(crate) routine: u32,
}

/// The node above every root.
pub(crate) const TOP: u32 = 0;

/// The shadow stack, the call tree and the cycles spent in each of its
/// cells.
#[derive(Debug, Clone)]
pub(crate) struct Stack {
    pub(crate) routines: Vec<Routine>,
    routine_ids: FxHashMap<Routine, u32>,
    /// The routine id of [`Routine::Sub`] by address, once made
    /// (`u32::MAX` before): a `JSR` finds its routine without hashing.
    sub_ids: Vec<u32>,
    pub(crate) calls: Vec<Calls>,
    /// Open frames of each routine: only the outermost one's cycles count
    /// as its inclusive (a recursive routine's inner calls are inside it).
    active: Vec<u32>,
    pub(crate) nodes: Vec<Node>,
    node_ids: FxHashMap<(u32, u32), u32>,
    /// By routine: the parent and node it was last entered under. A
    /// routine called from one place over and over finds its node here
    /// instead of hashing.
    node_cache: Vec<(u32, u32)>,
    /// Cycles by cell; a cell is a node and a label.
    pub(crate) cells: Vec<u64>,
    pub(crate) cell_keys: Vec<(u32, u32)>,
    cell_ids: FxHashMap<(u32, u32), u32>,
    /// By label (plus one, so none is 0): the node and cell it was last
    /// charged in. A loop through a few labels finds its cells here
    /// instead of hashing at every label it crosses.
    cell_cache: Vec<(u32, u32)>,
    frames: Vec<Frame>,
    main: u32,
    /// The node code runs in now (the top frame's, or `main`'s).
    top: u32,
    /// The addresses of the label last charged (the first and how many;
    /// none once the frames change) and its cell in the top node: an
    /// instruction in them is charged with one comparison.
    span: (u16, u32),
    span_cell: u32,
    /// The command running now (an index into the commands seen).
    pub(crate) command: Option<u32>,
}

impl Stack {
    pub(crate) fn new() -> Stack {
        let mut stack = Stack {
            routines: Vec::new(),
            routine_ids: FxHashMap::default(),
            sub_ids: vec![u32::MAX; 0x1_0000],
            calls: Vec::new(),
            active: Vec::new(),
            nodes: vec![Node {
                parent: TOP,
                routine: u32::MAX,
            }],
            node_ids: FxHashMap::default(),
            node_cache: Vec::new(),
            cells: Vec::new(),
            cell_keys: Vec::new(),
            cell_ids: FxHashMap::default(),
            cell_cache: Vec::new(),
            frames: Vec::new(),
            main: TOP,
            top: TOP,
            span: (0, 0),
            span_cell: 0,
            command: None,
        };
        let main = stack.routine_id(Routine::Main);
        stack.main = stack.child(TOP, main);
        stack.top = stack.main;
        stack.calls[main as usize].calls = 1;
        stack.cell(stack.main, u32::MAX);
        stack
    }

    fn routine_id(&mut self, routine: Routine) -> u32 {
        if let Some(&id) = self.routine_ids.get(&routine) {
            return id;
        }
        let id = index(self.routines.len());
        self.routines.push(routine.clone());
        self.routine_ids.insert(routine, id);
        self.calls.push(Calls::default());
        self.active.push(0);
        self.node_cache.push((u32::MAX, 0));
        id
    }

    /// The id of the routine a `JSR` to `target` enters.
    fn sub_id(&mut self, target: u16) -> u32 {
        let id = self.sub_ids[usize::from(target)];
        if id != u32::MAX {
            return id;
        }
        let id = self.routine_id(Routine::Sub(target));
        self.sub_ids[usize::from(target)] = id;
        id
    }

    fn child(&mut self, parent: u32, routine: u32) -> u32 {
        if let Some(&(cached, node)) = self.node_cache.get(routine as usize)
            && cached == parent
        {
            return node;
        }
        let node = *self.node_ids.entry((parent, routine)).or_insert_with(|| {
            self.nodes.push(Node { parent, routine });
            index(self.nodes.len() - 1)
        });
        if let Some(slot) = self.node_cache.get_mut(routine as usize) {
            *slot = (parent, node);
        }
        node
    }

    fn cell(&mut self, node: u32, label: u32) -> u32 {
        *self.cell_ids.entry((node, label)).or_insert_with(|| {
            self.cells.push(0);
            self.cell_keys.push((node, label));
            index(self.cells.len() - 1)
        })
    }

    /// The node code runs in now.
    fn node(&self) -> u32 {
        self.top
    }

    fn frames_changed(&mut self) {
        self.top = self.frames.last().map_or(self.main, |frame| frame.node);
        self.span = (0, 0);
    }

    /// Counts `cycles` spent at `address` (named by `labels`), in the
    /// frame on top.
    #[inline(always)]
    pub(crate) fn charge(&mut self, address: u16, cycles: u64, labels: &Labels) {
        let (first, len) = self.span;
        if u32::from(address.wrapping_sub(first)) < len {
            self.cells[self.span_cell as usize] += cycles;
        } else {
            self.charge_elsewhere(address, cycles, labels);
        }
    }

    /// [`Stack::charge`] at an address out of the last label's: its
    /// label's cell found, and its addresses made the span.
    #[inline(never)]
    fn charge_elsewhere(&mut self, address: u16, cycles: u64, labels: &Labels) {
        let label = labels.of(address);
        let cell = self.cached_cell(label);
        self.span = labels.span(label);
        self.span_cell = cell;
        self.cells[cell as usize] += cycles;
    }

    /// The cell of `label` in the top frame's node.
    fn cached_cell(&mut self, label: u32) -> u32 {
        let node = self.top;
        let slot = label.wrapping_add(1) as usize;
        match self.cell_cache.get(slot) {
            Some(&(cached, cell)) if cached == node => cell,
            _ => {
                let cell = self.cell(node, label);
                if slot >= self.cell_cache.len() {
                    self.cell_cache.resize(slot + 1, (u32::MAX, 0));
                }
                self.cell_cache[slot] = (node, cell);
                cell
            }
        }
    }

    fn push(&mut self, routine: u32, ends: Ends, entry: u64, times: u64) {
        let parent = match ends {
            Ends::Interrupt { .. } => TOP,
            Ends::Return { .. } | Ends::Command => self.node(),
        };
        self.push_under(parent, routine, ends, entry, times);
    }

    fn push_under(&mut self, parent: u32, routine: u32, ends: Ends, entry: u64, times: u64) {
        let node = self.child(parent, routine);
        self.calls[routine as usize].calls += times;
        self.active[routine as usize] += 1;
        self.frames.push(Frame {
            node,
            routine,
            entry,
            ends,
            times,
        });
        self.frames_changed();
    }

    fn pop(&mut self, now: u64) {
        let Some(frame) = self.frames.pop() else {
            return;
        };
        self.frames_changed();
        let cost = now.saturating_sub(frame.entry);
        let active = &mut self.active[frame.routine as usize];
        *active = active.saturating_sub(1);
        let outermost = *active == 0;
        let calls = &mut self.calls[frame.routine as usize];
        if calls.ended == 0 || cost < calls.min {
            calls.min = cost;
        }
        if calls.ended == 0 || cost > calls.max {
            calls.max = cost;
            calls.worst_node = frame.node;
            calls.worst_command = self.command;
        }
        calls.ended += frame.times;
        if outermost {
            calls.inclusive += cost * frame.times;
        }
    }

    /// Ends the frames whose return slots a push at S = `s_before`
    /// writes over (the 6502 stack is 256 bytes and wraps), or
    /// whose slots lie above S (an address pulled and discarded): they can
    /// never be returned from, and left open the shadow stack would grow
    /// without bound under a `JSR` that never returns.
    fn overwritten(&mut self, s_before: u8, now: u64) {
        while let Some(frame) = self.frames.last() {
            let (return_s, slot) = match frame.ends {
                Ends::Return { return_s } => (return_s, 2),
                Ends::Interrupt { return_s } => (return_s, 3),
                Ends::Command => break,
            };
            // The frame's slot runs from return_s down by `slot` bytes; a
            // push that starts below it leaves it whole.
            if u16::from(s_before) + slot <= u16::from(return_s) {
                break;
            }
            self.pop(now);
        }
    }

    /// A `JSR` to `target` with S at `s_before` before it, ending at `now`.
    pub(crate) fn call(&mut self, target: u16, s_before: u8, now: u64, times: u64) {
        self.overwritten(s_before, now);
        let routine = self.sub_id(target);
        self.push(routine, Ends::Return { return_s: s_before }, now, times);
    }

    /// The routine at `target` entered by the host as a `JSR` would (S at
    /// `s_before` before the return address), at `now`: a root.
    pub(crate) fn entered(&mut self, target: u16, s_before: u8, now: u64) {
        self.overwritten(s_before, now);
        let routine = self.sub_id(target);
        self.push_under(TOP, routine, Ends::Return { return_s: s_before }, now, 1);
    }

    /// An IRQ, NMI or BRK whose sequence began at `entry`, with S at
    /// `s_before` before its pushes.
    pub(crate) fn interrupt(&mut self, routine: Routine, s_before: u8, entry: u64) {
        self.overwritten(s_before, entry);
        let routine = self.routine_id(routine);
        self.push(routine, Ends::Interrupt { return_s: s_before }, entry, 1);
    }

    /// An `RTS` (or, with `interrupts`, an `RTI` or a `TXS`) that left S
    /// at `s`: the frames it returned from end.
    pub(crate) fn unwind(&mut self, s: u8, interrupts: bool, now: u64) {
        while let Some(frame) = self.frames.last() {
            let ends = match frame.ends {
                Ends::Return { return_s } => return_s <= s,
                Ends::Interrupt { return_s } => interrupts && return_s <= s,
                Ends::Command => false,
            };
            if !ends {
                break;
            }
            self.pop(now);
        }
    }

    /// A command arrived (`text`, the `index`th seen) at `now`.
    pub(crate) fn command_begins(&mut self, text: &str, index: u32, now: u64) {
        self.command_ends(now);
        let routine = self.routine_id(Routine::Command(text.to_owned()));
        self.push(routine, Ends::Command, now, 1);
        self.command = Some(index);
    }

    /// The command running ends at `now` (its frame and any frame above
    /// it); nothing if none runs. Returns whether one did.
    pub(crate) fn command_ends(&mut self, now: u64) -> bool {
        let Some(depth) = self
            .frames
            .iter()
            .rposition(|frame| frame.ends == Ends::Command)
        else {
            return false;
        };
        while self.frames.len() > depth {
            self.pop(now);
        }
        self.command = None;
        true
    }

    /// Ends every frame still open, at `now`.
    pub(crate) fn close(&mut self, now: u64) {
        while !self.frames.is_empty() {
            self.pop(now);
        }
        self.command = None;
    }

    /// The routines from the root down to `node`.
    pub(crate) fn path(&self, mut node: u32) -> Vec<u32> {
        let mut path = Vec::new();
        while node != TOP {
            let Some(n) = self.nodes.get(node as usize) else {
                break;
            };
            path.push(n.routine);
            node = n.parent;
        }
        path.reverse();
        path
    }
}

fn index(len: usize) -> u32 {
    u32::try_from(len).unwrap_or(u32::MAX)
}
