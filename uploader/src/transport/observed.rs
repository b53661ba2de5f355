//! A line with something done after every exchange on it: the CLI and the
//! project runner use it to show what a virtual robot's card and world
//! scripts printed while a command or a transcript runs, as it happens.

use std::time::Duration;

use super::Transport;
use crate::Result;

/// What [`Observed`] does after each exchange (a send, a receive, a
/// clearing of the input, a look at why the robot is silent).
pub trait Exchanged {
    /// Called after each exchange, whatever its result.
    fn exchanged(&mut self);
}

/// `inner`, with `after` told of each exchange on it.
#[derive(Debug)]
pub struct Observed<T, A> {
    inner: T,
    after: A,
}

impl<T, A> Observed<T, A> {
    /// `inner`, telling `after` of each exchange.
    pub fn new(inner: T, after: A) -> Self {
        Observed { inner, after }
    }

    /// The line and its observer, to use both at once.
    pub fn parts_mut(&mut self) -> (&mut T, &mut A) {
        (&mut self.inner, &mut self.after)
    }
}

impl<T: Transport, A: Exchanged> Observed<T, A> {
    fn then<R>(&mut self, result: R) -> R {
        self.after.exchanged();
        result
    }
}

impl<T: Transport, A: Exchanged> Transport for Observed<T, A> {
    fn send(&mut self, bytes: &[u8]) -> Result<()> {
        let result = self.inner.send(bytes);
        self.then(result)
    }
    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        let result = self.inner.receive(into, timeout);
        self.then(result)
    }
    fn baud(&self) -> u32 {
        self.inner.baud()
    }
    fn set_baud(&mut self, baud: u32) -> Result<()> {
        self.inner.set_baud(baud)
    }
    fn now(&self) -> Duration {
        self.inner.now()
    }
    fn clear_input(&mut self) -> Result<()> {
        let result = self.inner.clear_input();
        self.then(result)
    }
    fn name(&self) -> String {
        self.inner.name()
    }
    fn diagnose_silence(&mut self) -> Result<()> {
        let result = self.inner.diagnose_silence();
        self.then(result)
    }
}
