//! Example IV: virtual fingers — commands to a logical finger, mapped onto physical ones.

use imrs_sim::hand::{Hand, finger_joints};

use crate::special::{Joint, Tactile};
use crate::{Behavior, Cx, Declare, Flow, Kind, Schema, SchemaError, ports};

/// `[VF_k () () ()]`: no ports, no variables, a null behaviour. An instance `VF_k_i` says
/// that physical finger `i` belongs to virtual finger `k` in this context.
#[derive(Debug, Clone, Copy, Default)]
pub struct Vf<const K: u32>;

/// `VF_` and `K` in decimal, built when the schema is compiled, so that every virtual
/// finger has a name of its own, however many a hand has.
struct VfName<const K: u32>;

impl<const K: u32> VfName<K> {
    /// `VF_`, then up to ten digits (a `u32` has no more).
    const BYTES: ([u8; 13], usize) = {
        let mut bytes = [0u8; 13];
        bytes[0] = b'V';
        bytes[1] = b'F';
        bytes[2] = b'_';
        let mut digits = 1;
        let mut rest = K / 10;
        while rest > 0 {
            digits += 1;
            rest /= 10;
        }
        let (mut at, mut rest) = (3 + digits, K);
        while at > 3 {
            at -= 1;
            bytes[at] = b'0' + (rest % 10) as u8;
            rest /= 10;
        }
        (bytes, 3 + digits)
    };
    const NAME: &'static str = match std::str::from_utf8(Self::BYTES.0.split_at(Self::BYTES.1).0) {
        Ok(name) => name,
        Err(_) => panic!("a virtual finger's name is ASCII"),
    };
}

impl<const K: u32> Schema for Vf<K> {
    const NAME: &'static str = VfName::<K>::NAME;
    type Ports = ();

    fn set_up(&mut self, _: &Cx) -> Result<(), SchemaError> {
        Ok(())
    }

    async fn behavior(&mut self, _: &(), _: &Cx) -> Behavior {
        std::future::pending().await
    }
}

ports! {
    /// The r-schema's ports: the fingertip, both joints' positions, both joints' commands.
    pub struct ClosefingerPorts {
        in tin: bool = "Tin",
        in p1: f32 = "P1",
        in p2: f32 = "P2",
        out d1: f32 = "D1",
        out d2: f32 = "D2",
    }
}

/// `N = [T_i - F_i]`: closes finger `i` (its instance number) until its tip touches:
/// sensing `Tactile_i`, motor the finger's two `Joint`s.
#[derive(Debug)]
pub struct Closefinger {
    hand: Hand,
    del: f32,
}

impl Closefinger {
    /// Closes its finger by `del` per pass on each joint.
    pub fn new(hand: &Hand, del: f32) -> Self {
        Self {
            hand: hand.clone(),
            del,
        }
    }
}

impl Schema for Closefinger {
    const NAME: &'static str = "Closefinger";
    const KIND: Kind = Kind::TaskUnit;
    type Ports = ClosefingerPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<ClosefingerPorts, SchemaError> {
        let finger = cx.number();
        let ports: ClosefingerPorts = Declare::declare(cx.me());
        let tactile = cx.instantiate_as(finger, Tactile::new(&self.hand))?;
        cx.connect(&tactile.ports().contact, &ports.tin);
        let [proximal, distal] = finger_joints(finger as usize);
        for (joint, (position, desired)) in [proximal, distal]
            .into_iter()
            .zip([(&ports.p1, &ports.d1), (&ports.p2, &ports.d2)])
        {
            let joint = cx.instantiate_as(joint as u32, Joint::new(&self.hand))?;
            cx.connect(&joint.ports().position, position);
            cx.connect(desired, &joint.ports().desired);
        }
        Ok(ports)
    }

    async fn behavior(&mut self, p: &ClosefingerPorts, _: &Cx) -> Behavior {
        let touching = p.tin.read().await?;
        let (p1, p2) = (p.p1.read().await?, p.p2.read().await?);
        let step = if touching { 0.0 } else { self.del };
        p.d1.write(p1 + step).await?;
        p.d2.write(p2 + step).await?;
        Ok(Flow::Continue)
    }
}

/// `(FORALL VF_k_i DO N(i)() ENDFOR)`: one [`Closefinger`] for each finger in virtual
/// finger `K`, then stops; the `Closefinger`s go on in the assemblage it is in.
#[derive(Debug)]
pub struct Grasp<const K: u32> {
    hand: Hand,
    del: f32,
}

impl<const K: u32> Grasp<K> {
    /// Closes virtual finger `K` by `del` per pass.
    pub fn new(hand: &Hand, del: f32) -> Self {
        Self {
            hand: hand.clone(),
            del,
        }
    }
}

impl<const K: u32> Schema for Grasp<K> {
    const NAME: &'static str = "Grasp";
    type Ports = ();

    fn set_up(&mut self, _: &Cx) -> Result<(), SchemaError> {
        Ok(())
    }

    async fn behavior(&mut self, _: &(), cx: &Cx) -> Behavior {
        for finger in cx.forall::<Vf<K>>() {
            cx.instantiate_as(finger.number(), Closefinger::new(&self.hand, self.del))?;
        }
        Ok(Flow::Stop)
    }
}
