//! A peer process for the crate's tests: it owns or uses a port across processes.
//!
//! - `ipc_peer owner CELL PORT`: exports PORT (users ASKER and ASKER_2, two at most), and
//!   answers each number with its double, after waiting the number's milliseconds if it is
//!   over 1000 (so that a test can catch it mid-rendezvous). Prints `ready` once exported.
//! - `ipc_peer tight-owner CELL PORT`: the same, with PORT declared TIGHT.
//! - `ipc_peer responder CELL PORT`: exports the `RESPONSE` port PORT (user ASKER), whose
//!   response handler answers each number with its triple. Prints `ready` once exported.
//! - `ipc_peer listener CELL PORT MODULE N`: imports the `SENDALL` port PORT (owner
//!   BROADCASTER) for MODULE, answers N broadcasts with their doubles, printing each.
//! - `ipc_peer answerer CELL PORT MODULE N`: imports the `CALLALL` port PORT (owner CALLER)
//!   for MODULE, whose response handler answers N queries with their quadruples, printing
//!   each.
//! - `ipc_peer child CELL PORT MODULE N`: imports the `QUERY` port PORT (owner PARENT) for
//!   MODULE, whose response handler answers N queries with five times their number, printing
//!   each; then exits.
//! - `ipc_peer frame-child CELL PORT MODULE N`: imports the `QUERY` port PORT of frames
//!   built in place (owner PARENT) for MODULE, whose response handler answers N queries as
//!   `inspector` below does, with every further word seven times the frame's, printing
//!   `answered` after each; then exits.
//! - `ipc_peer frame-listener CELL PORT MODULE N FACTOR`: imports the `SENDALL` port PORT
//!   of frames built in place (owner CAMERA) for MODULE, which answers N broadcasts as
//!   `inspector` below does, with every further word FACTOR times the frame's, printing
//!   `answered` after each; then exits.
//! - `ipc_peer frame-answerer CELL PORT MODULE N FACTOR`: the same for the `CALLALL` port
//!   PORT (owner CAMERA), answered by MODULE's response handler.
//! - `ipc_peer camera CELL PORT N`: exports PORT, a `SENDALL` port of frames built in
//!   place (user LEFT), prints `ready`, and once LEFT is attached broadcasts N frames, each
//!   built in a loan with word 4 its number (from 1). Each answer must say that LEFT read
//!   the frame in place (word 0 is 1), and hold three times the number in word 4; it
//!   exits with 2 at the first that does not.
//! - `ipc_peer parent CELL PORT N`: exports PORT, a `QUERY` port of numbers (owner PARENT,
//!   user CHILD), prints `ready`, and once CHILD is attached asks it 1..=N; each answer
//!   must be five times the question, or it exits with 2.
//! - `ipc_peer caller CELL PORT N`: the same for PORT, a `CALLALL` port of numbers (owner
//!   CALLER, user ANSWERER): each question goes to ANSWERER's response handler.
//! - `ipc_peer announcer CELL PORT N`: the same for PORT, a `SENDALL` port of numbers
//!   (owner ANNOUNCER, user HEARER): each number is broadcast, and HEARER replies.
//! - `ipc_peer vision CELL PORT`: exports PORT, a port of 64 KiB frames built in place
//!   (`Shared`; users CAMERA and CAMERA_2), and answers each frame with one whose word 0 is
//!   1 if the frame was read in place (not a copy of its own), word 1 the sum of the
//!   previous frame's words as read now — after it was answered — word 2 the sum of this
//!   frame's, word 3 1 if the answer was built in a loan of shared memory, and every further
//!   word three times the frame's. The answer is built in a loan made for the frame; for a
//!   frame whose word 3 is 1, in one made for the previous frame. Prints `ready` once
//!   exported.
//! - `ipc_peer inspector CELL PORT`: exports PORT, a `RESPONSE` port of frames built in
//!   place (user ASKER), whose response handler answers each frame as `vision` does, with
//!   every further word five times the frame's, building its answer in a reply loan.
//!   Prints `ready` once exported.
//! - `ipc_peer user CELL PORT MODULE N`: imports PORT for MODULE and asks the doubles of
//!   1..=N, printing each; prints the error and exits with 2 if refused.

use std::process::ExitCode;
use std::time::Duration;

use imrs_ipc::{FromBytes, Imported, Remote, ZeroCopySend, export, import};
use imrs_ports::{AnyUser, Port, PortSpec, ProcessType, Shared, usage};

/// The tests' message: the same type, by name, size and alignment, as theirs.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Number")]
struct Number {
    value: u64,
}

/// The tests' frame: 64 KiB, the same by name, size and alignment as theirs.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Frame")]
struct Frame {
    words: [u64; 8192],
}

impl Default for Frame {
    fn default() -> Self {
        Self { words: [0; 8192] }
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("a tokio runtime starts");
    let result = runtime.block_on(async {
        match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
            ["owner", cell, port] => owner(cell, port, ProcessType::Indep).await,
            ["tight-owner", cell, port] => owner(cell, port, ProcessType::Tight).await,
            ["responder", cell, port] => responder(cell, port).await,
            ["vision", cell, port] => vision(cell, port).await,
            ["camera", cell, port, n] => camera(cell, port, n).await,
            ["parent", cell, port, n] => parent(cell, port, n).await,
            ["caller", cell, port, n] => caller(cell, port, n).await,
            ["announcer", cell, port, n] => announcer(cell, port, n).await,
            ["inspector", cell, port] => inspector(cell, port).await,
            ["listener", cell, port, module, n] => listener(cell, port, module, n).await,
            ["answerer", cell, port, module, n] => answerer(cell, port, module, n).await,
            ["child", cell, port, module, n] => child(cell, port, module, n).await,
            ["frame-child", cell, port, module, n] => frame_child(cell, port, module, n).await,
            ["frame-listener", cell, port, module, n, factor] => {
                frame_listener(cell, port, module, n, factor).await
            }
            ["frame-answerer", cell, port, module, n, factor] => {
                frame_answerer(cell, port, module, n, factor).await
            }
            ["user", cell, port, module, n] => user(cell, port, module, n).await,
            _ => Err(
                "usage: ipc_peer owner|tight-owner|responder|vision|inspector CELL PORT \
                 | camera|parent|caller CELL PORT N \
                 | user|listener|answerer|child|frame-child CELL PORT MODULE N \
                 | frame-listener|frame-answerer CELL PORT MODULE N FACTOR"
                    .into(),
            ),
        }
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            println!("error: {error}");
            ExitCode::from(2)
        }
    }
}

type Error = Box<dyn std::error::Error>;

async fn owner(cell: &str, port: &str, process_type: ProcessType) -> Result<(), Error> {
    let port: Port<Number, Number, usage::Receive, AnyUser, 2> = Port::new(
        PortSpec::new(port, "DOUBLER")
            .user_list(["ASKER", "ASKER_2"])
            .process_type(process_type),
    );
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    let mut owner = port.owner()?;
    loop {
        let (number, reply) = owner.receive().await?;
        if number.value > 1000 {
            tokio::time::sleep(Duration::from_millis(number.value)).await;
        }
        reply.reply(Number {
            value: 2 * number.value,
        });
    }
}

async fn vision(cell: &str, port: &str) -> Result<(), Error> {
    let port: Port<Shared<Frame>, Shared<Frame>, usage::Receive, AnyUser, 2> =
        Port::new(PortSpec::new(port, "VISION").user_list(["CAMERA", "CAMERA_2"]));
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    let mut vision = port.owner()?;
    let sum = |frame: &Frame| {
        frame
            .words
            .iter()
            .fold(0u64, |sum, &word| sum.wrapping_add(word))
    };
    // The last frame, kept past its reply: it must still read as it did.
    let mut previous: Option<Shared<Frame>> = None;
    loop {
        let (mut frame, reply) = vision.receive().await?;
        let mut answer: Shared<Frame> = match &previous {
            Some(previous) if frame.words[3] == 1 => previous.loan_reply(),
            _ => frame.loan_reply(),
        };
        answer.words[0] = u64::from(!frame.is_writable());
        answer.words[1] = previous.as_deref().map_or(0, sum);
        answer.words[2] = sum(&frame);
        answer.words[3] = u64::from(!answer.buffer().is::<Box<Frame>>());
        for (out, word) in answer.words.iter_mut().zip(frame.words.iter()).skip(4) {
            *out = word.wrapping_mul(3);
        }
        reply.reply(answer);
        previous = Some(frame);
    }
}

async fn inspector(cell: &str, port: &str) -> Result<(), Error> {
    let port: Port<Shared<Frame>, Shared<Frame>, usage::Response, AnyUser, 1> =
        Port::new(PortSpec::new(port, "INSPECTOR").user_list(["ASKER"]));
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    let factor = 5;
    let mut inspector = port.answer(port.owner_module().clone(), inspect)?;
    loop {
        inspector.serve(&factor).await?;
    }
}

/// Answers `frame` with one built in a loan made for it: word 0 is 1 if the frame was read
/// in place (not a copy of its own), word 3 is 1 if the answer lies in a loan, and every
/// further word is `factor` times the frame's.
fn inspect(factor: &u64, mut frame: Shared<Frame>) -> Shared<Frame> {
    let mut answer: Shared<Frame> = frame.loan_reply();
    answer.words[0] = u64::from(!frame.is_writable());
    answer.words[3] = u64::from(!answer.buffer().is::<Box<Frame>>());
    for (out, word) in answer.words.iter_mut().zip(frame.words.iter()).skip(4) {
        *out = word.wrapping_mul(*factor);
    }
    answer
}

async fn frame_child(cell: &str, port: &str, module: &str, n: &str) -> Result<(), Error> {
    let imported = import::<Imported<Shared<Frame>, Shared<Frame>, usage::Query>, _>(
        &Remote::new(cell)?,
        port,
        "PARENT",
        module,
    )?;
    answer(imported.port(), module, inspect, 7, n).await?;
    imported.settled().await;
    Ok(())
}

async fn camera(cell: &str, port: &str, n: &str) -> Result<(), Error> {
    let port: Port<Shared<Frame>, Shared<Frame>, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new(port, "CAMERA").user_list(["LEFT"]));
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    let mut camera = port.owner()?;
    camera.peer_attached().await;
    for seed in 1..=n.parse::<u64>()? {
        let mut frame = camera.loan()?;
        frame.words[4] = seed;
        let broadcast = camera.send_all(frame).await?;
        let (in_place, word) = (broadcast.first.words[0], broadcast.first.words[4]);
        if in_place != 1 || word != 3 * seed {
            return Err(format!("frame {seed}: answered {word}, read in place: {in_place}").into());
        }
    }
    Ok(())
}

async fn parent(cell: &str, port: &str, n: &str) -> Result<(), Error> {
    let port: Port<Number, Number, usage::Query, AnyUser, 1> =
        Port::new(PortSpec::new(port, "PARENT").user_list(["CHILD"]));
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    let mut parent = port.owner()?;
    parent.peer_attached().await;
    five_times_each(n, async |value| {
        Ok(parent.query(Number { value }).await?.value)
    })
    .await
}

async fn caller(cell: &str, port: &str, n: &str) -> Result<(), Error> {
    let port: Port<Number, Number, usage::CallAll, AnyUser, 1> =
        Port::new(PortSpec::new(port, "CALLER").user_list(["ANSWERER"]));
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    let mut caller = port.owner()?;
    caller.peer_attached().await;
    five_times_each(n, async |value| {
        Ok(caller.call_all(Number { value }).await?.first.value)
    })
    .await
}

async fn announcer(cell: &str, port: &str, n: &str) -> Result<(), Error> {
    let port: Port<Number, Number, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new(port, "ANNOUNCER").user_list(["HEARER"]));
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    let mut announcer = port.owner()?;
    announcer.peer_attached().await;
    five_times_each(n, async |value| {
        Ok(announcer.send_all(Number { value }).await?.first.value)
    })
    .await
}

/// Asks 1..=`n` with `ask`: each answer must be five times the question.
async fn five_times_each(
    n: &str,
    mut ask: impl AsyncFnMut(u64) -> Result<u64, Error>,
) -> Result<(), Error> {
    for value in 1..=n.parse::<u64>()? {
        let answer = ask(value).await?;
        if answer != 5 * value {
            return Err(format!("asked {value}, answered {answer}").into());
        }
    }
    Ok(())
}

async fn frame_listener(
    cell: &str,
    port: &str,
    module: &str,
    n: &str,
    factor: &str,
) -> Result<(), Error> {
    let imported = import::<Imported<Shared<Frame>, Shared<Frame>, usage::SendAll>, _>(
        &Remote::new(cell)?,
        port,
        "CAMERA",
        module,
    )?;
    let factor = factor.parse::<u64>()?;
    let mut listening = imported.port().user_named(module)?;
    for _ in 0..n.parse::<u64>()? {
        let (frame, reply) = listening.receive().await?;
        reply.reply(inspect(&factor, frame));
        println!("answered");
    }
    imported.settled().await;
    Ok(())
}

async fn frame_answerer(
    cell: &str,
    port: &str,
    module: &str,
    n: &str,
    factor: &str,
) -> Result<(), Error> {
    let imported = import::<Imported<Shared<Frame>, Shared<Frame>, usage::CallAll>, _>(
        &Remote::new(cell)?,
        port,
        "CAMERA",
        module,
    )?;
    answer(imported.port(), module, inspect, factor.parse()?, n).await?;
    imported.settled().await;
    Ok(())
}

async fn responder(cell: &str, port: &str) -> Result<(), Error> {
    let port: Port<Number, Number, usage::Response, AnyUser, 1> =
        Port::new(PortSpec::new(port, "TRIPLER").user_list(["ASKER"]));
    let _exported = export(&Remote::new(cell)?, &port)?;
    println!("ready");
    // The module's state: the factor its handler answers with.
    let factor = 3;
    let mut responder = port.answer(port.owner_module().clone(), multiply)?;
    loop {
        responder.serve(&factor).await?;
    }
}

async fn listener(cell: &str, port: &str, module: &str, n: &str) -> Result<(), Error> {
    let imported = import::<Imported<Number, Number, usage::SendAll>, _>(
        &Remote::new(cell)?,
        port,
        "BROADCASTER",
        module,
    )?;
    let mut listening = imported.port().user_named(module)?;
    for _ in 0..n.parse::<u64>()? {
        let (number, reply) = listening.receive().await?;
        println!("{}", number.value);
        reply.reply(Number {
            value: 2 * number.value,
        });
    }
    // The last reply crosses after the module gave it: ends once it has.
    imported.settled().await;
    Ok(())
}

async fn answerer(cell: &str, port: &str, module: &str, n: &str) -> Result<(), Error> {
    let imported = import::<Imported<Number, Number, usage::CallAll>, _>(
        &Remote::new(cell)?,
        port,
        "CALLER",
        module,
    )?;
    answer(imported.port(), module, multiply, 4, n).await?;
    imported.settled().await;
    Ok(())
}

async fn child(cell: &str, port: &str, module: &str, n: &str) -> Result<(), Error> {
    let imported = import::<Imported<Number, Number, usage::Query>, _>(
        &Remote::new(cell)?,
        port,
        "PARENT",
        module,
    )?;
    answer(imported.port(), module, multiply, 5, n).await?;
    imported.settled().await;
    Ok(())
}

/// A response handler's answer: `factor` times the number.
fn multiply(factor: &u64, number: Number) -> Number {
    Number {
        value: factor * number.value,
    }
}

/// Answers `n` queries on `port` as `module`, each as `handler` does with `factor`, from a
/// response handler; prints `answered` after each.
async fn answer<M, U>(
    port: &Port<M, M, U, AnyUser, 1>,
    module: &str,
    handler: fn(&u64, M) -> M,
    factor: u64,
    n: &str,
) -> Result<(), Error>
where
    M: Send + 'static,
    U: usage::Answers,
{
    let mut answering = port.answer(module, handler)?;
    for _ in 0..n.parse::<u64>()? {
        answering.serve(&factor).await?;
        println!("answered");
    }
    Ok(())
}

async fn user(cell: &str, port: &str, module: &str, n: &str) -> Result<(), Error> {
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &Remote::new(cell)?,
        port,
        "DOUBLER",
        module,
    )?;
    let mut asker = imported.port().user_named(module)?;
    for value in 1..=n.parse::<u64>()? {
        let double = asker.send(Number { value }).await?;
        println!("{}", double.value);
    }
    Ok(())
}
