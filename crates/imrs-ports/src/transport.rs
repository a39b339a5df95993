//! What a transport or an executor plugs into a port: the seam beneath the user's API.
//!
//! A cell author never needs this module. A transport (ports across processes, across
//! hosts) lends the memory messages are built in, hands broadcasts to where its users read
//! them, and moves messages in a spinning wait's own thread ([`PortTransport`], [`Pump`]).
//! An executor says which module is polled ([`Presence`]) and reads how urgent a wake is
//! ([`waking`]). These are kept apart from `Port`'s inherent methods, which are the user's,
//! because each can silently change what a port promises (parked waits turn off a TIGHT
//! port's spinning).

use crate::end::End;
use crate::loom::Ordering;
use crate::port::Port;
use crate::shared::LoanError;
use crate::usage::Usage;
use crate::user_list::UserList;

pub use crate::presence::Presence;
pub use crate::pump::Pump;
pub use crate::urgency::waking;

/// A transport's hooks on a port. Sealed: implemented for [`Port`] only.
pub trait PortTransport<Req>: sealed::Sealed {
    /// Lends the memory the port's messages are built in: each [`End::loan`] of the port
    /// calls `lender`. For a transport whose messages lie in memory of its own (shared
    /// memory, across processes); without a lender, a loan is on the heap. The first lender
    /// set holds, for every handle of the port.
    ///
    /// [`End::loan`]: crate::End::loan
    fn lend_with(self, lender: impl Fn() -> Result<Req, LoanError> + Send + Sync + 'static)
    -> Self;

    /// Hands each broadcast of the port (`SENDALL` or `CALLALL`) to its transport before
    /// the port clones it for each user: the port clones what `hand` returns. For a
    /// transport whose users all read one copy where it lies (shared memory, across
    /// processes): a broadcast built elsewhere, such as the heap, is moved there once, and
    /// every user's clone reads that one copy, rather than each being copied on its way.
    /// The first set holds, for every handle of the port.
    fn broadcast_with(self, hand: impl Fn(Req) -> Req + Send + Sync + 'static) -> Self;

    /// Makes every wait on the port park at once, whatever its process type says: for a
    /// transport whose side of the rendezvous is a task on the same runtime as the module's,
    /// which a TIGHT port's spin would keep off its worker until the spin ends. Holds for
    /// every handle of the port.
    fn park_waits(&self);

    /// Gives `pump` a turn between the looks of each wait on the port that spins (a TIGHT
    /// port's), in the waiting module's own thread: for a transport that can move a message
    /// there rather than in a task of its own, which would first have to be woken. The
    /// ends the transport itself waits on should park ([`End::park_waits`]). The first pump
    /// set holds, for every handle of the port.
    ///
    /// [`End::park_waits`]: EndTransport::park_waits
    fn pump_with(&self, pump: impl Pump);
}

/// A transport's hook on an end.
pub trait EndTransport: sealed::Sealed {
    /// Makes this end's waits park at once, whatever the port's process type says: for an
    /// end a transport waits on in a task of its own, beside a module that spins on the
    /// port's other end ([`PortTransport::pump_with`]).
    fn park_waits(&mut self);
}

mod sealed {
    pub trait Sealed {}
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> sealed::Sealed for Port<Req, Rep, U, L, N> {}

impl<Req, Rep, U, L, const N: usize> PortTransport<Req> for Port<Req, Rep, U, L, N>
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: Usage,
    L: UserList,
{
    /// Lends the memory the port's messages are built in: each [`End::loan`] of the port
    /// calls `lender`. For a transport whose messages lie in memory of its own (shared
    /// memory, across processes); without a lender, a loan is on the heap. The first lender
    /// set holds, for every handle of the port.
    ///
    /// [`End::loan`]: crate::End::loan
    fn lend_with(
        self,
        lender: impl Fn() -> Result<Req, LoanError> + Send + Sync + 'static,
    ) -> Self {
        let _first_holds = self.core().hooks_to_set().lender.set(Box::new(lender));
        self
    }

    /// Hands each broadcast of the port (`SENDALL` or `CALLALL`) to its transport before
    /// the port clones it for each user: the port clones what `hand` returns. For a
    /// transport whose users all read one copy where it lies (shared memory, across
    /// processes): a broadcast built elsewhere, such as the heap, is moved there once, and
    /// every user's clone reads that one copy, rather than each being copied on its way.
    /// The first set holds, for every handle of the port.
    fn broadcast_with(self, hand: impl Fn(Req) -> Req + Send + Sync + 'static) -> Self {
        let _first_holds = self.core().hooks_to_set().handing.set(Box::new(hand));
        self
    }

    /// Makes every wait on the port park at once, whatever its process type says: for a
    /// transport whose side of the rendezvous is a task on the same runtime as the module's,
    /// which a TIGHT port's spin would keep off its worker until the spin ends. Holds for
    /// every handle of the port.
    fn park_waits(&self) {
        self.core().parked.store(true, Ordering::Relaxed);
    }

    /// Gives `pump` a turn between the looks of each wait on the port that spins (a TIGHT
    /// port's), in the waiting module's own thread: for a transport that can move a message
    /// there rather than in a task of its own, which would first have to be woken. The
    /// ends the transport itself waits on should park ([`End::park_waits`]). The first pump
    /// set holds, for every handle of the port.
    ///
    /// [`End::park_waits`]: EndTransport::park_waits
    fn pump_with(&self, pump: impl Pump) {
        let _first_holds = self.core().hooks_to_set().pump.set(Box::new(pump));
    }
}

impl<Req, Rep, U: Usage> sealed::Sealed for End<Req, Rep, U> {}

impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> EndTransport for End<Req, Rep, U> {
    fn park_waits(&mut self) {
        self.set_parked();
    }
}

#[cfg(test)]
mod tests {
    use super::PortTransport;
    use crate::{Port, PortSpec, ProcessType, usage};

    #[test]
    fn a_tight_port_whose_waits_are_parked_spins_no_more_on_any_end() {
        let port = Port::<u32, u32, usage::Receive>::new(
            PortSpec::new("TIGHT", "OWNER").process_type(ProcessType::Tight),
        );
        let owner = port.owner().unwrap();
        assert!(owner.attachment.spins() > 0);
        // Set through another handle: it holds for every end, attached before or after.
        port.clone().park_waits();
        let user = port.user_named("USER").unwrap();
        assert_eq!(owner.attachment.spins(), 0);
        assert_eq!(user.attachment.spins(), 0);
        // Ports of other process types never spun.
        let loose = Port::<u32, u32, usage::Receive>::new(PortSpec::new("LOOSE", "OWNER"));
        assert_eq!(loose.owner().unwrap().attachment.spins(), 0);
    }
}
