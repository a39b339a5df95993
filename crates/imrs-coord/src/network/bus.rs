//! A CSMA/DCR bus and its worst-case delay.

use std::time::Duration;

/// The longest packet of each station in the seed's worst case, in bytes (frame overhead
/// included): the coordinator's "trajectory information and start order" (`X_t` = 148 B)
/// and nine robots' "position information" (`X_p` = 51 B).
pub const SEED_CASE: [usize; 10] = [148, 51, 51, 51, 51, 51, 51, 51, 51, 51];

/// The delay the seed reports for [`SEED_CASE`] "with the standard network parameters".
pub const SEED_D_MAX: Duration = Duration::from_micros(604);

/// A bus: its data rate, its timing parameters and its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bus {
    /// `R`, in bits per second.
    pub rate: f64,
    /// `IFS`, the interframe spacing.
    pub ifs: Duration,
    /// The jam time.
    pub jam: Duration,
    /// `τ`, the end-to-end propagation delay.
    pub propagation: Duration,
    /// `ε`, the time a station takes to detect a collision.
    pub detection: Duration,
    /// The shortest frame the bus carries, in bytes with the preamble; shorter packets are
    /// padded to it. `None`: packets go as they are (as the seed counts them).
    pub min_frame: Option<usize>,
    /// How long a slot of a resolution period lasts when its station does not send.
    pub slot: Duration,
}

impl Bus {
    /// IEEE 802.3 at 10 Mb/s on a coaxial bus of `length` metres, with the standard's
    /// parameters:
    ///
    /// | parameter | value | source |
    /// |---|---|---|
    /// | `R` | 10 Mb/s | 802.3, 10BASE5 |
    /// | `IFS` | 96 bit times = 9.6 µs | 802.3 `interFrameGap` |
    /// | `jam` | 32 bits = 3.2 µs | 802.3 `jamSize` |
    /// | `τ` | `length` / (0.77 c): 0.433 µs per 100 m | 802.3 10BASE5 coax, minimum propagation velocity 0.77 c |
    /// | `ε` | 0.9 µs | the 10BASE5 MAU's budget for signalling a collision (900 ns); the i82596's own figure is not at hand |
    /// | slot | 512 bit times = 51.2 µs | 802.3 `slotTime`, the value the seed calls standard |
    ///
    /// No minimum frame: the seed counts a 51-byte position packet as 51 bytes, where
    /// 802.3 would pad it to 72 (64 plus the 8-byte preamble). [`Bus::padded`] pads.
    pub fn ieee_802_3(length: f64) -> Self {
        const C: f64 = 299_792_458.0;
        Self {
            rate: 10e6,
            ifs: Duration::from_nanos(9_600),
            jam: Duration::from_nanos(3_200),
            propagation: Duration::from_secs_f64(length / (0.77 * C)),
            detection: Duration::from_nanos(900),
            min_frame: None,
            slot: Duration::from_nanos(51_200),
        }
    }

    /// The same bus, padding packets shorter than 802.3's minimum frame (64 bytes plus
    /// the 8-byte preamble).
    pub fn padded(self) -> Self {
        Self {
            min_frame: Some(72),
            ..self
        }
    }

    /// `γ = 2τ + jam + ε`: from a collision to the moment the stations resolve it.
    pub fn gamma(&self) -> Duration {
        2 * self.propagation + self.jam + self.detection
    }

    /// `X/R`: how long a packet of `bytes` takes on the wire.
    pub fn transmission(&self, bytes: usize) -> Duration {
        let bytes = self.min_frame.map_or(bytes, |min| bytes.max(min));
        Duration::from_secs_f64(bytes as f64 * 8.0 / self.rate)
    }

    /// One station's turn: `X/R + τ + IFS`.
    pub fn turn(&self, bytes: usize) -> Duration {
        self.transmission(bytes) + self.propagation + self.ifs
    }

    /// The longest a message waits for the bus under the simulated model
    /// ([`simulate`](super::simulate)), for stations whose longest packets are `longest`:
    /// [`slot_bound`](super::slot_bound) with this bus's slot. It is [`Bus::d_max`] or more;
    /// more where an empty slot is longer than `IFS` or than a station's turn, as 802.3's
    /// is.
    pub fn worst_wait(&self, longest: &[usize]) -> Duration {
        super::slot_bound(self, longest, self.slot).max(self.d_max(longest))
    }

    /// `D_max` for stations whose longest packets are `longest` (bytes, one per station):
    /// the worst wait of a message for the bus, from the moment its station is ready to send
    /// it. With no station, nothing waits: zero.
    pub fn d_max(&self, longest: &[usize]) -> Duration {
        if longest.is_empty() {
            return Duration::ZERO;
        }
        let turns: Duration = longest.iter().map(|&bytes| self.turn(bytes)).sum();
        turns + self.ifs + self.gamma() + self.propagation
    }
}
