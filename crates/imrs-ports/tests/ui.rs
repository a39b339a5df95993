//! Misuse that must not compile: one misuse per file in `tests/ui/`, each with the
//! compiler's message beside it. Refresh the messages with `TRYBUILD=overwrite cargo test`.

#[test]
fn misuse_does_not_compile() {
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/*.rs");
}
