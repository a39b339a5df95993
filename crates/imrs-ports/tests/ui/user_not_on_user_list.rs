use imrs_ports::{Named, Port, PortSpec, usage, user_list};

struct ScrewInCard;
impl Named for ScrewInCard {
    const NAME: &'static str = "SCREW_IN_CARD";
}
struct Gate;
impl Named for Gate {
    const NAME: &'static str = "GATE";
}

user_list! {
    /// CARD_IN_PLACE: USERLIST=(SCREW_IN_CARD).
    CardInPlaceUsers = [ScrewInCard];
}

fn main() {
    let port = Port::<(), i32, usage::Send, CardInPlaceUsers>::new(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"));
    // GATE has no business with the card in place.
    let _ = port.user::<Gate>();
}
