//! A port whose messages cannot cross processes does not compile when it is wired for
//! IPC, and the compiler says why. Refresh the message with `TRYBUILD=overwrite cargo test`.

#[test]
fn a_message_that_cannot_cross_processes_does_not_compile() {
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/*.rs");
}
