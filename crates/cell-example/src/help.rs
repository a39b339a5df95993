//! What a cell operator would want where the Appendix writes `{signal for help}`.

use std::future::Future;
use std::time::Duration;

use imrs_core::Ctx;
use imrs_ports::{End, usage};
use imrs_sim::{DeviceError, PalletId};

use crate::alarms::{AlarmKind, alarm};
use crate::devices::RelayDevice;

/// How long an operator takes to reset a faulted robot.
pub const RESET_TIME: Duration = Duration::from_secs(1);

/// Runs a device operation; when the robot faults, raises an alarm, waits for the
/// operator's reset, and tries once more.
pub async fn retried<S, T, F, Fut>(
    ctx: &Ctx<S>,
    what: &str,
    mut operation: F,
) -> Result<T, DeviceError>
where
    S: Send + Sync + 'static,
    F: FnMut() -> Fut,
    Fut: Future<Output = Result<T, DeviceError>>,
{
    match operation().await {
        Err(DeviceError::RobotFault { robot }) => {
            alarm(
                ctx,
                AlarmKind::RobotFault,
                format!("{robot} faulted while {what}: reset by the operator, retrying"),
            );
            ctx.delay(RESET_TIME).await;
            operation().await
        }
        other => other,
    }
}

/// Runs a device operation until it succeeds, with an alarm and a reset after each failure:
/// for moves that must complete (leaving the shared zone).
pub async fn insisted<S, F, Fut>(ctx: &Ctx<S>, what: &str, mut operation: F)
where
    S: Send + Sync + 'static,
    F: FnMut() -> Fut,
    Fut: Future<Output = Result<(), DeviceError>>,
{
    while let Err(error) = operation().await {
        alarm(
            ctx,
            AlarmKind::of_error(&error),
            format!("{error} while {what}: reset by the operator, retrying"),
        );
        ctx.delay(RESET_TIME).await;
    }
}

/// A freeze-relay driver task (FREEZE_PALLET, FREEZE_CARD): it waits for a pallet to be held
/// in place, sends on `port` and waits for the module to let the pallet go, then frees it.
/// A jammed pallet is taken off the line, with an alarm.
pub async fn drive_relay<S>(
    ctx: &Ctx<S>,
    relay: &RelayDevice,
    port: &mut End<PalletId, (), usage::Send>,
) -> Result<(), DeviceError>
where
    S: Send + Sync + 'static,
{
    loop {
        match relay.wait_in_place().await {
            Ok(pallet) => {
                // Hold the pallet until the module (or a new copy of it) lets it go.
                while let Err(error) = ctx.send(port, pallet).await {
                    alarm(
                        ctx,
                        AlarmKind::NoAnswer,
                        format!("{pallet}: {error}; asking again"),
                    );
                    ctx.delay(RESET_TIME).await;
                }
                if let Err(error @ DeviceError::Jam { .. }) = relay.release().await {
                    alarm(
                        ctx,
                        AlarmKind::Jam,
                        format!("{error}: taking the pallet off the line"),
                    );
                    relay.clear_jam().await;
                }
            }
            Err(error @ DeviceError::Jam { .. }) => {
                alarm(
                    ctx,
                    AlarmKind::Jam,
                    format!("{error}: taking the pallet off the line"),
                );
                relay.clear_jam().await;
            }
            Err(error) => return Err(error),
        }
    }
}
