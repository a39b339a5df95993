use imrs_ports::{Named, Port, PortSpec, usage, user_list};

struct LoadCard;
impl Named for LoadCard {
    const NAME: &'static str = "LOAD_CARD";
}
struct ScrewInCard;
impl Named for ScrewInCard {
    const NAME: &'static str = "SCREW_IN_CARD";
}

user_list! {
    /// ASK_CHILD1: USERLIST=(LOAD_CARD).
    AskChild1Users = [LoadCard];
}

fn main() {
    let port = Port::<(), i32, usage::Query, AskChild1Users>::declare(PortSpec::new("ASK_CHILD1", "LOAD_IT"));
    // SCREW_IN_CARD answers ASK_CHILD2, not ASK_CHILD1.
    let _ = port.responder::<ScrewInCard, ()>(|_, ()| 0);
}
