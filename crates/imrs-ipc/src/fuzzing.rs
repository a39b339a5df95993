//! The code that reads what another process wrote into shared memory, reached from outside
//! for the fuzz targets in `fuzz/`. Built only under `cfg(fuzzing)`, which `cargo fuzz` sets:
//! not part of the API.

use imrs_ports::Name;
use zerocopy::FromBytes;

use crate::IpcError;
use crate::wire::{ReplyMeta, RequestMeta};

/// The module a request's header names, as the owner's bridge reads it; `None` for a header
/// it refuses as malformed. `bytes` are the header as a peer wrote it (the first bytes, if
/// more; `None` if fewer).
pub fn request_module(bytes: &[u8]) -> Option<Option<String>> {
    let (meta, _) = RequestMeta::read_from_prefix(bytes).ok()?;
    Some(meta.module().map(str::to_owned))
}

/// What an importer makes of the owner's answer to its connection, `bytes` being the
/// reply's header as a peer wrote it (`None` if too few).
pub fn connection_answer(
    bytes: &[u8],
    port: &Name,
    module: &str,
) -> Option<Result<bool, IpcError>> {
    let (meta, _) = ReplyMeta::read_from_prefix(bytes).ok()?;
    Some(crate::connect::answered(meta, port, module))
}
