//! A port keeps each side's waker and wakes it by reference: in steady state a round trip
//! clones no waker, though both sides wait and are woken at every message.

use std::future::Future;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::task::{Context, RawWaker, RawWakerVTable, Waker};

use imrs_ports::{Port, PortSpec, usage};

/// One task of the little executor below: woken or not, and how often its waker was cloned
/// and woken.
#[derive(Default)]
struct Task {
    woken: AtomicBool,
    clones: AtomicUsize,
    wakes: AtomicUsize,
}

const VTABLE: RawWakerVTable = RawWakerVTable::new(clone, wake, wake, drop_waker);

fn task_of(data: *const ()) -> &'static Task {
    // SAFETY: every waker of this vtable points at a leaked, so never freed, `Task`.
    unsafe { &*data.cast::<Task>() }
}

fn clone(data: *const ()) -> RawWaker {
    task_of(data).clones.fetch_add(1, Ordering::Relaxed);
    RawWaker::new(data, &VTABLE)
}

fn wake(data: *const ()) {
    let task = task_of(data);
    task.wakes.fetch_add(1, Ordering::Relaxed);
    task.woken.store(true, Ordering::Relaxed);
}

fn drop_waker(_: *const ()) {}

fn waker_of(task: &'static Task) -> Waker {
    // SAFETY: the vtable's functions keep the contract of `RawWaker`: the data is a `Task`
    // that lives for the whole program, and cloning or dropping a waker frees nothing.
    unsafe { Waker::from_raw(RawWaker::new(std::ptr::from_ref(task).cast(), &VTABLE)) }
}

type Job = Pin<Box<dyn Future<Output = ()>>>;

/// Polls each woken job in turn, on this thread, until both are done.
fn run(jobs: [(Job, &'static Task); 2]) {
    let mut jobs = jobs.map(|(job, task)| (Some(job), task, waker_of(task)));
    for (_, task, _) in &jobs {
        task.woken.store(true, Ordering::Relaxed);
    }
    while jobs.iter().any(|(job, _, _)| job.is_some()) {
        for (job, task, waker) in &mut jobs {
            let Some(future) = job else { continue };
            if !task.woken.swap(false, Ordering::Relaxed) {
                continue;
            }
            if future
                .as_mut()
                .poll(&mut Context::from_waker(waker))
                .is_ready()
            {
                *job = None;
            }
        }
    }
}

#[test]
fn a_round_trip_in_steady_state_clones_no_waker() {
    const WARM_UP: u32 = 10;
    const MEASURED: u32 = 1_000;
    let port = Port::<u32, u32, usage::Receive>::new(PortSpec::new("P", "OWNER"));
    let mut owner = port.owner().unwrap();
    let mut user = port.user_named("USER").unwrap();
    let server: &'static Task = Box::leak(Box::default());
    let sender: &'static Task = Box::leak(Box::default());
    let measured = std::sync::Arc::new(std::sync::Mutex::new(None));
    let noted = std::sync::Arc::clone(&measured);
    let serve: Job = Box::pin(async move {
        for _ in 0..WARM_UP + MEASURED {
            let (message, reply) = owner.receive().await.unwrap();
            reply.reply(message + 1);
        }
    });
    let send: Job = Box::pin(async move {
        for n in 0..WARM_UP {
            assert_eq!(user.send(n).await.unwrap(), n + 1);
        }
        let count = |task: &Task| {
            (
                task.clones.load(Ordering::Relaxed),
                task.wakes.load(Ordering::Relaxed),
            )
        };
        let before = [count(server), count(sender)];
        for n in 0..MEASURED {
            assert_eq!(user.send(n).await.unwrap(), n + 1);
        }
        *noted.lock().unwrap() = Some((before, [count(server), count(sender)]));
    });
    run([(serve, server), (send, sender)]);
    let ([(server_clones, server_wakes), (sender_clones, sender_wakes)], after) =
        measured.lock().unwrap().take().unwrap();
    let [
        (server_clones_after, server_wakes_after),
        (sender_clones_after, sender_wakes_after),
    ] = after;
    // Each side waited for the other at every message: the receive for the send, the send
    // for the reply.
    assert!(server_wakes_after - server_wakes >= MEASURED as usize);
    assert!(sender_wakes_after - sender_wakes >= MEASURED as usize);
    assert_eq!(
        (
            server_clones_after - server_clones,
            sender_clones_after - sender_clones
        ),
        (0, 0),
        "waker clones in {MEASURED} round trips (server, sender)"
    );
}
