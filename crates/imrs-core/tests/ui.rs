//! Misuse of a module's port operations that must not compile, each reported once, with the
//! compiler's message beside it. Refresh with `TRYBUILD=overwrite cargo test -p imrs-core --test ui`.

#[test]
fn misuse_does_not_compile() {
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/*.rs");
}
