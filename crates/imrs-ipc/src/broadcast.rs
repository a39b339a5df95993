//! A broadcast read in place by every user: a `SENDALL` or `CALLALL` port of [`Shared`]
//! messages sends each broadcast once, as a sample of a publish-subscribe service of its
//! own, which every user process reads where it lies. What each user's relay carries is
//! only a [`Ticket`]: which sample its broadcast is. The user process takes that sample
//! from its subscription, hands it to its module, and answers as for any message; the
//! sample's memory is let go when every process has dropped its last handle.
//!
//! The owner's loans are samples of the publisher, so a broadcast built in one crosses
//! with nothing copied. Its send is when the port first hands it on (`Shared`'s `Clone`,
//! which a broadcast makes for each user): the owner's own subscription then holds the
//! sample, so the owner's handles read it where it lies too. A message built anywhere else
//! (the heap) is copied into a sample once, when the port hands the broadcast over
//! ([`Port::broadcast_with`](imrs_ports::transport::PortTransport::broadcast_with)), and goes out
//! as one built in a loan does.

use std::any::Any;
use std::cmp::Ordering;
use std::collections::VecDeque;
use std::ptr::NonNull;
use std::sync::{Arc, Mutex, PoisonError};
use std::task::{Context, Poll};
use std::time::{SystemTime, UNIX_EPOCH};

use iceoryx2::node::Node;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use iceoryx2::sample_mut::SampleMut;
use iceoryx2::service::port_factory::PortFactory as _;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory;
use imrs_ports::shared::Buffer;
use imrs_ports::{LoanError, Name, ReplyHandle, Shared};
use zerocopy::FromBytes;

use crate::bridge::{MAX_PENDING, Svc, node, refusal, transport};
use crate::carry::{Answer, Asker, Carry, Held, Loan, Reply, lend_reply, lock};
use crate::export::attach::Forward;
use crate::import::Take;
use crate::{IpcError, Remote, Wire};

/// Which broadcast a user's relayed request stands for: its sample's number.
#[derive(Debug, Clone, Copy, Default, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc::Ticket")]
pub(crate) struct Ticket {
    seq: u64,
}

/// A broadcast's sample carries its number beside it.
type Outgoing<Req> = Publisher<Svc, Req, u64>;
type Incoming<Req> = Subscriber<Svc, Req, u64>;
type Delivered<Req> = Sample<Svc, Req, u64>;
type Building<Req> = SampleMut<Svc, Req, u64>;
type Service<Req> = PortFactory<Svc, Req, u64>;

/// How many samples one process may hold at once: its module's messages, and those that
/// came ahead of their tickets.
const HELD: usize = 4 * MAX_PENDING;

/// Opens port `port`'s broadcast service: the owner's process creates it, sized for
/// `users` user processes; a user's only opens it.
fn service<Req: Wire>(
    node: &Node<Svc>,
    remote: &Remote,
    port: &Name,
    users: Option<usize>,
) -> Result<Service<Req>, IpcError> {
    let builder = node
        .service_builder(&remote.service(port.as_str(), "broadcast")?)
        .publish_subscribe::<Req>()
        .user_header::<u64>();
    match users {
        // Each user process, the owner's own subscription, and one more for a user process
        // restarted before its dead one is swept; and for the owner's publisher, one more
        // for an owner exporting the port again while its last broadcast is still held.
        Some(users) => builder
            .max_publishers(2)
            .max_subscribers(users + 2)
            .max_nodes(users + 3)
            .history_size(0)
            .subscriber_max_buffer_size(users + MAX_PENDING)
            .subscriber_max_borrowed_samples(HELD)
            .open_or_create()
            .map_err(|error| transport(port, "opening its broadcasts", error)),
        None => builder.open().map_err(|error| refusal(port, &error)),
    }
}

/// The owner's side: the publisher its broadcasts are sent by, lending its samples.
pub(crate) struct Broadcaster<Req: Wire> {
    port: Name,
    station: Mutex<Station<Req>>,
}

struct Station<Req: Wire> {
    publisher: Outgoing<Req>,
    /// This process's own subscription, which holds each broadcast for as long as a handle
    /// here reads it.
    own: Incoming<Req>,
    /// The next broadcast's number. It starts at the wall clock's nanoseconds, so that an
    /// owner started again numbers after the one before, whose broadcasts a user process
    /// may still have queued.
    next: u64,
    /// A send failed: the publisher lends no more, so that the failed sample's memory,
    /// which its handles still read, is never written again.
    failed: bool,
    _service: Service<Req>,
    _node: Node<Svc>,
}

impl<Req: Wire> Broadcaster<Req> {
    /// Creates port `port`'s publisher, for `users` user processes.
    pub(crate) fn create(
        remote: &Remote,
        port: &Name,
        users: usize,
    ) -> Result<Arc<Self>, IpcError> {
        let node = node(port)?;
        let service = service::<Req>(&node, remote, port, Some(users))?;
        let publisher = service
            .publisher_builder()
            .max_loaned_samples(MAX_PENDING)
            .create()
            .map_err(|error| transport(port, "publishing its broadcasts", error))?;
        let own = service
            .subscriber_builder()
            .create()
            .map_err(|error| transport(port, "holding its broadcasts", error))?;
        let next = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |since| since.as_nanos() as u64);
        Ok(Arc::new(Self {
            port: port.clone(),
            station: Mutex::new(Station {
                publisher,
                own,
                next,
                failed: false,
                _service: service,
                _node: node,
            }),
        }))
    }

    /// A loan for the owner's message: a sample of the publisher, all zeros, built in
    /// place; on the heap once a send has failed.
    pub(crate) fn loan(self: &Arc<Self>) -> Result<Shared<Req>, LoanError> {
        let station = lock(&self.station);
        if station.failed {
            return Ok(Shared::default());
        }
        let mut loan = station.publisher.loan_uninit().map_err(|error| LoanError {
            port: self.port.clone(),
            detail: format!("{error:?}"),
        })?;
        // SAFETY: `Req: FromBytes` (a bound of `Wire`), so all zeros are one of its values;
        // the whole payload is written before it is assumed initialised.
        let sample = unsafe {
            loan.payload_mut().as_mut_ptr().write_bytes(0, 1);
            loan.assume_init()
        };
        drop(station);
        Ok(self.building(sample))
    }

    /// `message`, ready to be sent once for every user: in a sample of the publisher,
    /// copied there if it lies anywhere else (the heap). Left where it is if no sample can
    /// be had; it is then copied for each user it goes to.
    pub(crate) fn adopt(self: &Arc<Self>, message: Shared<Req>) -> Shared<Req> {
        if self.published(&message).is_some() {
            return message;
        }
        let copied = self.copied(&message);
        copied.map_or(message, |sample| self.building(sample))
    }

    /// The ticket for `message`, sent to one user: the broadcast it belongs to, sent now if
    /// it has not been. A message not in one of this publisher's samples is copied into
    /// one. `None` if it could not be sent.
    pub(crate) fn ticket(self: &Arc<Self>, message: Shared<Req>) -> Option<Ticket> {
        if let Some(publication) = self.published(&message) {
            return publication.sent().map(|(seq, _)| Ticket { seq });
        }
        let sample = self.copied(&message)?;
        lock(&self.station)
            .publish(sample)
            .map(|(seq, _)| Ticket { seq })
    }

    /// `message`'s sample, if it lies in one of this publisher's.
    fn published<'m>(self: &Arc<Self>, message: &'m Shared<Req>) -> Option<&'m Publication<Req>> {
        message
            .buffer()
            .downcast_ref::<Publication<Req>>()
            .filter(|publication| Arc::ptr_eq(&publication.broadcaster, self))
    }

    /// A sample of the publisher holding a copy of `message`; `None` if none can be had.
    fn copied(&self, message: &Req) -> Option<Building<Req>> {
        let station = lock(&self.station);
        if station.failed {
            return None;
        }
        let mut loan = station.publisher.loan_uninit().ok()?;
        // SAFETY: `message` is a valid `Req`, and the loan is a sample of its own in shared
        // memory, so the two do not overlap; the copy writes the whole payload before it is
        // assumed initialised.
        Some(unsafe {
            loan.payload_mut()
                .as_mut_ptr()
                .copy_from_nonoverlapping(message, 1);
            loan.assume_init()
        })
    }

    /// The owner's message in `sample`, still to be built or sent.
    fn building(self: &Arc<Self>, mut sample: Building<Req>) -> Shared<Req> {
        let payload = NonNull::from(sample.payload_mut());
        Shared::in_buffer(Publication {
            broadcaster: Arc::clone(self),
            payload,
            state: Mutex::new(State::Building(sample)),
        })
    }
}

impl<Req: Wire> Station<Req> {
    /// Sends `sample` to every subscriber: its number, and this process's hold on it.
    fn publish(&mut self, mut sample: Building<Req>) -> Option<(u64, Hold<Req>)> {
        let seq = self.next;
        self.next = self.next.wrapping_add(1);
        *sample.user_header_mut() = seq;
        if sample.send().is_err() {
            self.failed = true;
            return None;
        }
        // The send put it in every subscriber's queue, this process's own too.
        loop {
            match self.own.receive() {
                Ok(Some(held)) if *held.user_header() == seq => {
                    return Some((seq, Arc::new(Mutex::new(held))));
                }
                // One whose handles are all gone: nothing here reads it.
                Ok(Some(_)) => {}
                Ok(None) | Err(_) => {
                    self.failed = true;
                    return None;
                }
            }
        }
    }
}

/// A process's hold on a broadcast's sample: its memory stays as it is while held.
type Hold<Req> = Arc<Mutex<Delivered<Req>>>;

/// The owner's message, in a sample of the publisher.
struct Publication<Req: Wire> {
    broadcaster: Arc<Broadcaster<Req>>,
    /// Where the message lies, in the publisher's memory.
    payload: NonNull<Req>,
    state: Mutex<State<Req>>,
}

enum State<Req: Wire> {
    /// Being built by the owner's module.
    Building(Building<Req>),
    /// Sent as broadcast `seq`, held by this process's own subscription.
    Sent { seq: u64, hold: Hold<Req> },
    /// Its send failed. The memory stays mapped (the publisher lives while the
    /// broadcaster does) and unwritten (the publisher lends no more).
    Lost,
}

// SAFETY: `payload` is written only through `&mut self` while the sample is being built
// (`get_mut`), and otherwise only read (`Req: Sync`, a bound of `Wire`); what keeps its
// memory — the broadcaster, and the sample or the hold on it — may move between threads.
unsafe impl<Req: Wire> Send for Publication<Req> {}

impl<Req: Wire> Publication<Req> {
    /// The broadcast this message is, sent now if it has not been.
    fn sent(&self) -> Option<(u64, Hold<Req>)> {
        let mut state = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        if let State::Building(_) = &*state {
            let State::Building(sample) = std::mem::replace(&mut *state, State::Lost) else {
                unreachable!("the state was just seen to be building");
            };
            if let Some((seq, hold)) = lock(&self.broadcaster.station).publish(sample) {
                *state = State::Sent { seq, hold };
            }
        }
        match &*state {
            State::Sent { seq, hold } => Some((*seq, Arc::clone(hold))),
            State::Building(_) | State::Lost => None,
        }
    }
}

impl<Req: Wire> Buffer<Req> for Publication<Req> {
    fn get(&self) -> &Req {
        // SAFETY: `payload` lies in a sample of the broadcaster's publisher, whose memory
        // stays mapped while `self.broadcaster` lives. While the sample is being built, it is
        // written only through `&mut self`; once sent, this process's hold keeps it from
        // being lent again until `self` is gone; if its send failed, the publisher lends no
        // more. So it stays a valid `Req`, unwritten, for as long as the borrow of `self`.
        unsafe { self.payload.as_ref() }
    }

    fn get_mut(&mut self) -> Option<&mut Req> {
        match self.state.get_mut().unwrap_or_else(PoisonError::into_inner) {
            // SAFETY: `payload` is the sample's own payload, which is lent to this handle
            // alone while it is being built, and `&mut self` borrows that handle for as
            // long as the result. Every access goes through `payload`, so none is left
            // dangling by another borrow of the sample.
            State::Building(_) => Some(unsafe { self.payload.as_mut() }),
            State::Sent { .. } | State::Lost => None,
        }
    }

    /// Handing the message on sends it: the other handle reads the sent sample where it
    /// lies, as every user process does.
    fn share(&self) -> Option<Box<dyn Buffer<Req> + Send>> {
        let (seq, hold) = self.sent()?;
        Some(Box::new(Publication {
            broadcaster: Arc::clone(&self.broadcaster),
            payload: self.payload,
            state: Mutex::new(State::Sent { seq, hold }),
        }))
    }
}

/// On the owner's side, a remote user module's end of the real port, whose every message
/// is sent as a broadcast and relayed as its ticket.
pub(crate) struct Ticketing<T, Req: Wire> {
    pub(crate) taken: T,
    pub(crate) broadcaster: Arc<Broadcaster<Req>>,
}

impl<Req: Wire, Rep: Send + 'static, T: Take<Shared<Req>, Rep>> Take<Ticket, Rep>
    for Ticketing<T, Req>
{
    fn poll_next(&mut self, cx: &mut Context<'_>) -> Poll<Option<(Ticket, ReplyHandle<Rep>)>> {
        loop {
            let Poll::Ready(taken) = self.taken.poll_next(cx) else {
                return Poll::Pending;
            };
            let Some((message, reply)) = taken else {
                return Poll::Ready(None);
            };
            if let Some(ticket) = self.broadcaster.ticket(message) {
                return Poll::Ready(Some((ticket, reply)));
            }
            // Not sent: the user is not reached, and its reply is dropped unanswered.
            drop(reply);
        }
    }

    fn try_next(&mut self) -> Option<(Ticket, ReplyHandle<Rep>)> {
        loop {
            let (message, reply) = self.taken.try_next()?;
            if let Some(ticket) = self.broadcaster.ticket(message) {
                return Some((ticket, reply));
            }
        }
    }

    fn park(&mut self) {
        self.taken.park();
    }
}

/// A ticket as a user's process receives it: and, for one it must answer, the loan its
/// answer may be built in.
pub(crate) struct Ticketed {
    seq: u64,
    reply: Option<Arc<dyn LendReply>>,
}

/// Lends the reply to a request received, whatever its types.
trait LendReply: Send + Sync {
    fn lend_reply(&self) -> Option<Box<dyn Any + Send>>;
}

struct ReplyTo<Req: Wire, Rep: Wire>(Held<Req, Rep>);

impl<Req: Wire, Rep: Wire> LendReply for ReplyTo<Req, Rep> {
    fn lend_reply(&self) -> Option<Box<dyn Any + Send>> {
        lend_reply(&self.0)
    }
}

impl Carry<Ticket> for Ticketed {
    fn from_request<Rep: Wire>(request: &Held<Ticket, Rep>) -> Self {
        let seq = lock(request).payload().seq;
        Self {
            seq,
            reply: Some(Arc::new(ReplyTo(Arc::clone(request)))),
        }
    }

    fn from_answer(answer: Answer<Ticket>) -> Self {
        Self {
            seq: answer.payload().seq,
            reply: None,
        }
    }

    fn into_request<Rep: Wire>(self, client: &Asker<Ticket, Rep>) -> Option<Loan<Ticket, Rep>> {
        Ticket { seq: self.seq }.into_request(client)
    }

    fn into_reply<Req: Wire>(self, request: &Held<Req, Ticket>) -> Option<Reply<Ticket>> {
        Ticket { seq: self.seq }.into_reply(request)
    }
}

/// A user process's subscription to the port's broadcasts.
pub(crate) struct Inbox<Req: Wire> {
    subscriber: Incoming<Req>,
    /// A sample taken ahead of its ticket.
    early: VecDeque<Delivered<Req>>,
    _service: Service<Req>,
    _node: Node<Svc>,
}

impl<Req: Wire> Inbox<Req> {
    /// Subscribes to port `port`'s broadcasts: refused as an import is, if no owner
    /// created them or the processes disagree on their type.
    pub(crate) fn open(remote: &Remote, port: &Name) -> Result<Self, IpcError> {
        let node = node(port)?;
        let service = service::<Req>(&node, remote, port, None)?;
        let subscriber = service
            .subscriber_builder()
            .buffer_size(service.static_config().subscriber_max_buffer_size())
            .create()
            .map_err(|error| transport(port, "subscribing to its broadcasts", error))?;
        Ok(Self {
            subscriber,
            early: VecDeque::new(),
            _service: service,
            _node: node,
        })
    }

    /// Broadcast `seq`'s sample. Those before it went to other users (or were never
    /// announced) and are let go; `None` if it is not there.
    fn take(&mut self, seq: u64) -> Option<Delivered<Req>> {
        loop {
            let sample = match self.early.pop_front() {
                Some(sample) => sample,
                None => self.subscriber.receive().ok()??,
            };
            match (*sample.user_header()).cmp(&seq) {
                Ordering::Less => {}
                Ordering::Equal => return Some(sample),
                Ordering::Greater => {
                    self.early.push_front(sample);
                    return None;
                }
            }
        }
    }
}

/// On a user's side, the local port's owner end, fed the broadcasts its tickets name.
pub(crate) struct Tuned<E, Req: Wire> {
    pub(crate) end: E,
    pub(crate) inbox: Arc<Mutex<Inbox<Req>>>,
}

impl<Req: Wire, R: Send + 'static, E: Forward<Shared<Req>, R>> Forward<Ticketed, R>
    for Tuned<E, Req>
{
    async fn forward(&mut self, ticket: Ticketed) -> Option<R> {
        let sample = lock(&self.inbox).take(ticket.seq)?;
        let payload = NonNull::from(sample.payload());
        let heard = Heard {
            payload,
            hold: Arc::new(Mutex::new(sample)),
            reply: ticket.reply,
        };
        self.end.forward(Shared::in_buffer(heard)).await
    }
}

/// A broadcast a user's process received, read where the owner wrote it.
struct Heard<Req: Wire> {
    payload: NonNull<Req>,
    /// Keeps the sample, where `payload` lies.
    hold: Hold<Req>,
    /// Where the answer to it may be built.
    reply: Option<Arc<dyn LendReply>>,
}

// SAFETY: `payload` is only ever read (`Req: Sync`, a bound of `Wire`), and the sample it
// points into is kept by `hold`, which may move between threads.
unsafe impl<Req: Wire> Send for Heard<Req> {}

impl<Req: Wire> Buffer<Req> for Heard<Req> {
    fn get(&self) -> &Req {
        // SAFETY: `payload` is the payload of the sample `hold` keeps: shared memory that
        // stays mapped, at the same address, and unwritten (the publisher lends no sample
        // any subscriber holds) while held — at least as long as `self`. It was a valid
        // `Req` when sent, and `Req: FromBytes`, so it is one whatever was written.
        unsafe { self.payload.as_ref() }
    }

    fn get_mut(&mut self) -> Option<&mut Req> {
        None
    }

    fn share(&self) -> Option<Box<dyn Buffer<Req> + Send>> {
        Some(Box::new(Heard {
            payload: self.payload,
            hold: Arc::clone(&self.hold),
            reply: self.reply.clone(),
        }))
    }

    fn lend_reply(&self) -> Option<Box<dyn Any + Send>> {
        self.reply.as_ref()?.lend_reply()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell of its own for each test, so that tests run in parallel.
    fn remote(test: &str) -> Remote {
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |since| since.subsec_nanos());
        Remote::new(&format!("u{}-{test}-{nanos}", std::process::id())).unwrap()
    }

    #[test]
    fn a_loaned_broadcast_is_one_sample_whatever_its_users_and_is_let_go_with_its_handles() {
        let remote = remote("one-sample");
        let port = Name::from("FRAMES");
        let broadcaster = Broadcaster::<[u64; 32]>::create(&remote, &port, 3).unwrap();
        let mut inbox = Inbox::<[u64; 32]>::open(&remote, &port).unwrap();
        // More broadcasts than the publisher has samples to lend at once: each is let go.
        for round in 0..(3 * MAX_PENDING as u64) {
            let mut message = broadcaster.loan().unwrap();
            assert!(message.is_writable(), "a loan is built in place");
            message[7] = round;
            // A broadcast to three users hands each a clone: one send, shared by all.
            sent_once_to_three_users(&broadcaster, &mut inbox, &message, round);
            assert!(!message.is_writable(), "a broadcast sent is still written");
            // Changing it afterwards changes a copy: no user sees the change.
            let kept = message.clone();
            message[7] = u64::MAX;
            assert_eq!(kept[7], round);
        }
    }

    /// Hands `message` to three users, as a broadcast does: each clone reads `message`
    /// itself, their tickets name one broadcast, and a user process gets that one sample,
    /// with word 7 `round`, and no other.
    fn sent_once_to_three_users(
        broadcaster: &Arc<Broadcaster<[u64; 32]>>,
        inbox: &mut Inbox<[u64; 32]>,
        message: &Shared<[u64; 32]>,
        round: u64,
    ) {
        let clones: Vec<Shared<[u64; 32]>> = (0..3).map(|_| message.clone()).collect();
        for clone in &clones {
            assert!(std::ptr::eq(&**clone, &**message), "a clone is a copy");
        }
        let tickets: Vec<u64> = clones
            .into_iter()
            .map(|clone| broadcaster.ticket(clone).unwrap().seq)
            .collect();
        assert!(tickets.iter().all(|&seq| seq == tickets[0]));
        let sample = inbox.take(tickets[0]).unwrap();
        assert_eq!(sample.payload()[7], round);
        assert!(inbox.subscriber.receive().unwrap().is_none());
    }

    #[test]
    fn a_broadcast_on_the_heap_is_copied_into_one_sample_which_every_users_clone_reads() {
        let remote = remote("adopted");
        let port = Name::from("FRAMES");
        let broadcaster = Broadcaster::<[u64; 32]>::create(&remote, &port, 3).unwrap();
        let mut inbox = Inbox::<[u64; 32]>::open(&remote, &port).unwrap();
        // More broadcasts than the publisher has samples to lend at once: each is let go.
        for round in 0..(3 * MAX_PENDING as u64) {
            let mut message = Shared::new([0u64; 32]);
            message[7] = round;
            let adopted = broadcaster.adopt(message);
            assert!(
                adopted.buffer().is::<Publication<[u64; 32]>>(),
                "left on the heap"
            );
            // Adopting it again changes nothing.
            let at = std::ptr::from_ref(&*adopted);
            let adopted = broadcaster.adopt(adopted);
            assert!(std::ptr::eq(&*adopted, at), "copied again");
            sent_once_to_three_users(&broadcaster, &mut inbox, &adopted, round);
        }
    }

    #[test]
    fn a_message_still_on_the_heap_at_a_users_relay_is_copied_into_a_sample_for_it() {
        let remote = remote("heap");
        let port = Name::from("FRAMES");
        let broadcaster = Broadcaster::<[u64; 32]>::create(&remote, &port, 2).unwrap();
        let mut inbox = Inbox::<[u64; 32]>::open(&remote, &port).unwrap();
        let mut message = Shared::new([0u64; 32]);
        message[3] = 42;
        let first = broadcaster.ticket(message.clone()).unwrap().seq;
        let second = broadcaster.ticket(message).unwrap().seq;
        assert_ne!(first, second);
        // The user process whose ticket is the second lets the first go.
        assert_eq!(inbox.take(second).unwrap().payload()[3], 42);
        assert!(
            inbox.take(first).is_none(),
            "an earlier broadcast came back"
        );
    }

    #[test]
    fn an_owner_started_again_numbers_its_broadcasts_after_the_one_before() {
        let remote = remote("again");
        let port = Name::from("FRAMES");
        let before = Broadcaster::<u64>::create(&remote, &port, 1).unwrap();
        let last = before.ticket(Shared::new(1)).unwrap().seq;
        drop(before);
        let after = Broadcaster::<u64>::create(&remote, &port, 1).unwrap();
        assert!(after.ticket(Shared::new(2)).unwrap().seq > last);
    }
}
