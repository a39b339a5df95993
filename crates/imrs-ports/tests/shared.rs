//! Messages built in place (`Shared`): moved by handle, never copied, in one process; lent
//! by whoever the port says; and copied once, to the heap, only when a read-only message is
//! changed.

use std::any::Any;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use imrs_ports::shared::Buffer;
use imrs_ports::transport::PortTransport as _;
use imrs_ports::{LoanError, Name, Port, PortSpec, Shared, usage};

/// An image, too large to copy on every hop.
#[derive(Debug, Clone, PartialEq)]
struct Image {
    pixels: [u8; 4096],
}

impl Default for Image {
    fn default() -> Self {
        Self { pixels: [0; 4096] }
    }
}

type ImagePort = Port<Shared<Image>, Shared<u64>, usage::Receive>;

#[tokio::test]
async fn a_loaned_message_reaches_its_receiver_where_its_sender_built_it() {
    let port = ImagePort::new(PortSpec::new("IMAGE", "VISION"));
    let mut vision = port.owner().unwrap();
    let mut camera = port.user_named("CAMERA").unwrap();
    let mut image = camera.loan().unwrap();
    // No lender: the heap, starting from the default.
    assert!(image.buffer().is::<Box<Image>>());
    assert!(image.pixels.iter().all(|&pixel| pixel == 0));
    image.pixels[..10].fill(9);
    let built_at = image.pixels.as_ptr();
    let seeing = tokio::spawn(async move {
        let (image, reply) = vision.receive().await.unwrap();
        let read_at = image.pixels.as_ptr() as usize;
        let lit = image.pixels.iter().filter(|&&pixel| pixel == 9).count() as u64;
        reply.reply(Shared::new(lit));
        read_at
    });
    assert_eq!(*camera.send(image).await.unwrap(), 10);
    assert_eq!(
        seeing.await.unwrap(),
        built_at as usize,
        "the image was copied"
    );
}

/// A transport's memory that is read-only: what a message received from another process
/// lies in.
struct ReadOnly(Arc<Image>);

impl Buffer<Image> for ReadOnly {
    fn get(&self) -> &Image {
        &self.0
    }

    fn get_mut(&mut self) -> Option<&mut Image> {
        None
    }
}

#[test]
fn changing_a_read_only_message_copies_it_once_and_leaves_the_original_as_it_was() {
    let mut original = Image::default();
    original.pixels[0] = 1;
    let original = Arc::new(original);
    let mut message = Shared::in_buffer(ReadOnly(Arc::clone(&original)));
    assert!(!message.is_writable());
    assert_eq!(message.pixels[0], 1);
    message.pixels[1] = 2;
    assert!(message.is_writable());
    let copy_at = message.pixels.as_ptr();
    message.pixels[2] = 3;
    assert_eq!(message.pixels.as_ptr(), copy_at, "copied a second time");
    assert_eq!(&message.pixels[..3], &[1, 2, 3]);
    assert_eq!(&original.pixels[..3], &[1, 0, 0]);
    assert!(message.buffer().is::<Box<Image>>());
}

#[tokio::test]
async fn a_ports_lender_makes_every_loan_and_its_refusal_names_the_port() {
    let lent = Arc::new(AtomicUsize::new(0));
    let counted = Arc::clone(&lent);
    let port = ImagePort::new(PortSpec::new("IMAGE", "VISION")).lend_with(move || {
        // Two loans, then the transport's memory is used up.
        if counted.fetch_add(1, Ordering::SeqCst) >= 2 {
            return Err(LoanError {
                port: Name::from("IMAGE"),
                detail: "every sample is out".into(),
            });
        }
        let mut image = Image::default();
        image.pixels[0] = 7;
        Ok(Shared::new(image))
    });
    let camera = port.user_named("CAMERA").unwrap();
    let (first, second) = (camera.loan().unwrap(), camera.loan().unwrap());
    assert_eq!((first.pixels[0], second.pixels[0]), (7, 7));
    let refused = camera.loan().unwrap_err();
    assert_eq!(refused.port.as_str(), "IMAGE");
    assert!(refused.to_string().contains("IMAGE"), "{refused}");
    assert_eq!(lent.load(Ordering::SeqCst), 3);
    // The first lender holds: a second is ignored.
    let _ = port.clone().lend_with(|| Ok(Shared::new(Image::default())));
    assert!(camera.loan().is_err());
}

/// A transport's request that lends memory for its reply.
struct Lending(Image);

impl Buffer<Image> for Lending {
    fn get(&self) -> &Image {
        &self.0
    }

    fn get_mut(&mut self) -> Option<&mut Image> {
        Some(&mut self.0)
    }

    fn lend_reply(&self) -> Option<Box<dyn Any + Send>> {
        Some(Box::new(Shared::new(41u64)))
    }
}

#[test]
fn a_reply_is_loaned_where_the_transport_lends_it_and_on_the_heap_otherwise() {
    // The transport's memory, for the port's reply type.
    let request = Shared::in_buffer(Lending(Image::default()));
    assert_eq!(*request.loan_reply::<u64>(), 41);
    // A type the transport does not carry back: the heap, from the default.
    assert_eq!(*request.loan_reply::<u32>(), 0);
    // In one process: the heap.
    let request = Shared::new(Image::default());
    let reply = request.loan_reply::<u64>();
    assert!(reply.buffer().is::<Box<u64>>());
    assert_eq!(*reply, 0);
}

/// A transport's memory that no one writes, which it can share: what a message received
/// from another process lies in.
struct Received(Arc<Image>);

impl Buffer<Image> for Received {
    fn get(&self) -> &Image {
        &self.0
    }

    fn get_mut(&mut self) -> Option<&mut Image> {
        None
    }

    fn share(&self) -> Option<Box<dyn Buffer<Image> + Send>> {
        Some(Box::new(Received(Arc::clone(&self.0))))
    }
}

#[test]
fn a_clone_of_a_message_no_one_writes_reads_the_same_memory_and_a_writable_ones_is_a_copy() {
    let mut image = Image::default();
    image.pixels[0] = 5;
    let memory = Arc::new(image);
    let received = Shared::in_buffer(Received(Arc::clone(&memory)));
    let clone = received.clone();
    assert_eq!(clone.pixels.as_ptr(), memory.pixels.as_ptr(), "copied");
    assert_eq!(Arc::strong_count(&memory), 3);
    // The memory is let go when the last handle is.
    drop(received);
    assert_eq!(Arc::strong_count(&memory), 2);
    // Changing the clone copies it, once, and leaves the memory as it was.
    let mut changed = clone.clone();
    changed.pixels[0] = 6;
    assert_eq!(
        (changed.pixels[0], clone.pixels[0], memory.pixels[0]),
        (6, 5, 5)
    );
    drop((clone, changed));
    assert_eq!(Arc::strong_count(&memory), 1);

    // Writable, on the heap: the clone is a copy, and neither sees the other's changes.
    let mut original = Shared::new(Image::default());
    let mut copy = original.clone();
    assert_ne!(copy.pixels.as_ptr(), original.pixels.as_ptr());
    original.pixels[0] = 1;
    copy.pixels[0] = 2;
    assert_eq!((original.pixels[0], copy.pixels[0]), (1, 2));
    // Read-only, but not shareable: copied to the heap.
    let unshared = Shared::in_buffer(ReadOnly(Arc::clone(&memory)));
    let copy = unshared.clone();
    assert!(copy.buffer().is::<Box<Image>>());
    assert_eq!(copy.pixels[0], 5);
}

#[tokio::test]
async fn a_broadcast_of_a_message_no_one_writes_reaches_every_user_where_it_lies() {
    let port = Port::<Shared<Image>, Shared<u64>, usage::SendAll, imrs_ports::AnyUser, 3>::new(
        PortSpec::new("FRAME", "CAMERA"),
    );
    let mut camera = port.owner().unwrap();
    let mut users: Vec<_> = ["VISION", "GRIPPER", "LOGGER"]
        .into_iter()
        .map(|module| port.user_named(module).unwrap())
        .collect();
    let mut frame = Image::default();
    frame.pixels[..3].fill(1);
    let memory = Arc::new(frame);
    let reading = users
        .drain(..)
        .map(|mut user| {
            tokio::spawn(async move {
                let (frame, reply) = user.receive().await.unwrap();
                let read_at = frame.pixels.as_ptr() as usize;
                reply.reply(Shared::new(
                    frame.pixels.iter().map(|&p| u64::from(p)).sum(),
                ));
                read_at
            })
        })
        .collect::<Vec<_>>();
    let broadcast = camera
        .send_all(Shared::in_buffer(Received(Arc::clone(&memory))))
        .await
        .unwrap();
    assert_eq!(*broadcast.first, 3);
    for user in reading {
        assert_eq!(
            user.await.unwrap(),
            memory.pixels.as_ptr() as usize,
            "a user's frame was copied"
        );
    }
}

#[tokio::test]
async fn a_broadcast_is_handed_to_the_transport_once_and_every_user_reads_what_it_made() {
    let port = Port::<Shared<Image>, Shared<u64>, usage::SendAll, imrs_ports::AnyUser, 3>::new(
        PortSpec::new("FRAME", "CAMERA"),
    );
    // The transport moves each broadcast into memory of its own, which it shares.
    let handed = Arc::new(std::sync::Mutex::new(Vec::<Arc<Image>>::new()));
    let into_memory = Arc::clone(&handed);
    let port = port.broadcast_with(move |frame: Shared<Image>| {
        let memory = Arc::new((*frame).clone());
        into_memory.lock().unwrap().push(Arc::clone(&memory));
        Shared::in_buffer(Received(memory))
    });
    // The first set holds, for every handle of the port.
    let _ignored = port
        .clone()
        .broadcast_with(|_| panic!("a second hand replaced the first"));
    let mut camera = port.owner().unwrap();

    // Refused before it is posted: the sender gets its own message back, not handed on.
    let mut frame = Image::default();
    frame.pixels[0] = 7;
    let refused = camera.send_all(Shared::new(frame)).await.unwrap_err();
    let imrs_ports::BroadcastError::NoUsers { message, .. } = refused else {
        panic!("a broadcast to nobody was not refused for it: {refused:?}");
    };
    assert!(message.buffer().is::<Box<Image>>(), "handed on, unsent");
    assert!(handed.lock().unwrap().is_empty());

    let users: Vec<_> = ["VISION", "GRIPPER", "LOGGER"]
        .into_iter()
        .map(|module| port.user_named(module).unwrap())
        .collect();
    let reading = users
        .into_iter()
        .map(|mut user| {
            tokio::spawn(async move {
                let mut read_at = Vec::new();
                for _ in 0..2 {
                    let (frame, reply) = user.receive().await.unwrap();
                    read_at.push(frame.pixels.as_ptr() as usize);
                    reply.reply(Shared::new(u64::from(frame.pixels[0])));
                }
                read_at
            })
        })
        .collect::<Vec<_>>();
    for value in [1, 2] {
        let mut frame = Image::default();
        frame.pixels[0] = value;
        let broadcast = camera.send_all(Shared::new(frame)).await.unwrap();
        assert_eq!(*broadcast.first, u64::from(value));
    }
    let handed: Vec<usize> = handed
        .lock()
        .unwrap()
        .iter()
        .map(|memory| memory.pixels.as_ptr() as usize)
        .collect();
    assert_eq!(handed.len(), 2, "not handed on once a broadcast");
    for user in reading {
        assert_eq!(user.await.unwrap(), handed, "a user read a copy of its own");
    }
}
