//! A log's memory is bounded: it keeps its most recent records up to its capacity, counts the
//! ones it forgot, and still streams every record to its subscribers.

use std::sync::{Arc, Mutex};

use imrs_core::{Log, Record};

#[derive(Debug, Clone, PartialEq)]
struct Tick(u64);

impl Record for Tick {}

#[test]
fn a_log_keeps_its_capacity_of_the_most_recent_records_and_streams_all() {
    let log = Log::with_capacity(100);
    let streamed = Arc::new(Mutex::new(0u64));
    let count = Arc::clone(&streamed);
    log.subscribe(move |_: &Tick| *count.lock().unwrap() += 1);
    for tick in 0..10_000 {
        log.record(Tick(tick));
    }
    assert_eq!(log.len(), 100);
    assert_eq!(log.forgotten(), 9_900);
    assert_eq!(log.snapshot().first(), Some(&Tick(9_900)));
    assert_eq!(log.snapshot().last(), Some(&Tick(9_999)));
    assert_eq!(*streamed.lock().unwrap(), 10_000);
}

#[test]
fn a_log_keeps_sixty_five_thousand_records_by_default_and_none_when_told() {
    let log = Log::new();
    for tick in 0..(Log::<Tick>::DEFAULT_CAPACITY as u64 + 10) {
        log.record(Tick(tick));
    }
    assert_eq!(log.len(), Log::<Tick>::DEFAULT_CAPACITY);
    assert_eq!(log.forgotten(), 10);
    log.forget_events();
    assert!(log.is_empty());
    log.record(Tick(0));
    assert!(log.is_empty());
}
