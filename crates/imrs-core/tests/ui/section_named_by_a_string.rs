use imrs_core::prelude::*;

// A section is a value made once, not a string written again at each use.
fn main() {
    let _ = ModuleSpec::new("PALLETIZER", ())
        .task("PALLETIZER", |ctx| async move {
            ctx.section("PLACE", ctx.delay(std::time::Duration::from_secs(1))).await;
            Ok(())
        });
}
