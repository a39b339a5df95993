//! What carries the chip cell's ports between its processes (`--processes`): iceoryx2
//! between processes of one host, or zenoh between hosts (`--transport zenoh`). The lines'
//! modules do not know which: an imported port is a local port either way. Zenoh is there
//! in a build with the `zenoh` feature.

use std::fmt;
use std::sync::Arc;

use imrs_ports::usage::Usage;
use imrs_ports::{AnyUser, Port};

/// A message that crosses on either carrier: a fixed-size record iceoryx2 reads in place,
/// and a `serde` type zenoh carries in CDR.
#[cfg(feature = "zenoh")]
pub trait Crossing: imrs_ipc::Wire + imrs_zenoh::Message {}

#[cfg(feature = "zenoh")]
impl<T: imrs_ipc::Wire + imrs_zenoh::Message> Crossing for T {}

/// A message that crosses: a fixed-size record iceoryx2 reads in place.
#[cfg(not(feature = "zenoh"))]
pub trait Crossing: imrs_ipc::Wire {}

#[cfg(not(feature = "zenoh"))]
impl<T: imrs_ipc::Wire> Crossing for T {}

/// A port that either carrier exports.
#[cfg(feature = "zenoh")]
pub trait Exportable<W>: imrs_ipc::Export<W> + imrs_zenoh::Export {}

#[cfg(feature = "zenoh")]
impl<W, P: imrs_ipc::Export<W> + imrs_zenoh::Export> Exportable<W> for P {}

/// A port that iceoryx2 exports.
#[cfg(not(feature = "zenoh"))]
pub trait Exportable<W>: imrs_ipc::Export<W> {}

#[cfg(not(feature = "zenoh"))]
impl<W, P: imrs_ipc::Export<W>> Exportable<W> for P {}

/// A usage whose ports of `Req` and `Rep` either carrier imports: iceoryx2 here, zenoh by
/// [`ZenohImport`].
pub trait Importable<Req: Crossing, Rep: Crossing>: ZenohImport<Req, Rep> {
    /// Imports `port` from another process of `remote`'s cell.
    fn import_ipc(
        remote: &imrs_ipc::Remote,
        port: &str,
        owner: &str,
        module: &str,
    ) -> Result<Imported<Req, Rep, Self>, CarrierError>;
}

impl<Req: Crossing, Rep: Crossing, U: ZenohImport<Req, Rep>> Importable<Req, Rep> for U
where
    imrs_ipc::Imported<Req, Rep, U>: imrs_ipc::Import<(Req, Rep)>,
{
    fn import_ipc(
        remote: &imrs_ipc::Remote,
        port: &str,
        owner: &str,
        module: &str,
    ) -> Result<Imported<Req, Rep, U>, CarrierError> {
        let imported =
            imrs_ipc::import::<imrs_ipc::Imported<Req, Rep, U>, _>(remote, port, owner, module)
                .map_err(CarrierError::Ipc)?;
        Ok(Arc::new(imported))
    }
}

/// How zenoh imports a usage's ports of `Req` and `Rep`.
#[cfg(feature = "zenoh")]
pub trait ZenohImport<Req: Crossing, Rep: Crossing>: Usage {
    /// Imports `port` from another host of `host`'s cell.
    fn import_zenoh(
        host: &imrs_zenoh::Host,
        port: &str,
        owner: &str,
        module: &str,
    ) -> impl Future<Output = Result<Imported<Req, Rep, Self>, CarrierError>> + Send;
}

#[cfg(feature = "zenoh")]
impl<Req: Crossing, Rep: Crossing, U: Usage> ZenohImport<Req, Rep> for U
where
    imrs_zenoh::Imported<Req, Rep, U>: imrs_zenoh::Import,
{
    async fn import_zenoh(
        host: &imrs_zenoh::Host,
        port: &str,
        owner: &str,
        module: &str,
    ) -> Result<Imported<Req, Rep, U>, CarrierError> {
        let imported =
            imrs_zenoh::import::<imrs_zenoh::Imported<Req, Rep, U>>(host, port, owner, module)
                .await
                .map_err(CarrierError::Zenoh)?;
        Ok(Arc::new(imported))
    }
}

/// In a build without the `zenoh` feature, nothing more than a usage.
#[cfg(not(feature = "zenoh"))]
pub trait ZenohImport<Req: Crossing, Rep: Crossing>: Usage {}

#[cfg(not(feature = "zenoh"))]
impl<Req: Crossing, Rep: Crossing, U: Usage> ZenohImport<Req, Rep> for U {}

/// A port imported from another process, by either carrier: its local stand-in.
pub trait Bridged<Req: Send + 'static, Rep: Send + 'static, U: Usage>: Send + Sync {
    /// The local port, whose owner side is the bridge to the real owner.
    fn port(&self) -> &Port<Req, Rep, U, AnyUser, 1>;
}

impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> Bridged<Req, Rep, U>
    for imrs_ipc::Imported<Req, Rep, U>
{
    fn port(&self) -> &Port<Req, Rep, U, AnyUser, 1> {
        imrs_ipc::Imported::port(self)
    }
}

#[cfg(feature = "zenoh")]
impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> Bridged<Req, Rep, U>
    for imrs_zenoh::Imported<Req, Rep, U>
{
    fn port(&self) -> &Port<Req, Rep, U, AnyUser, 1> {
        imrs_zenoh::Imported::port(self)
    }
}

/// An imported port, usable while this is held.
pub type Imported<Req, Rep, U = imrs_ports::usage::Receive> = Arc<dyn Bridged<Req, Rep, U>>;

/// An exported port, served while this is held.
pub enum Exported {
    /// To the processes of this host.
    Ipc(imrs_ipc::Exported),
    /// To the hosts of the cell.
    #[cfg(feature = "zenoh")]
    Zenoh(imrs_zenoh::Exported),
}

/// Why a port could not cross.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CarrierError {
    /// On iceoryx2.
    Ipc(imrs_ipc::IpcError),
    /// On zenoh.
    #[cfg(feature = "zenoh")]
    Zenoh(imrs_zenoh::ZenohError),
}

impl CarrierError {
    /// Whether nobody exports the port yet.
    pub fn is_no_owner(&self) -> bool {
        match self {
            CarrierError::Ipc(error) => matches!(error, imrs_ipc::IpcError::NoOwner { .. }),
            #[cfg(feature = "zenoh")]
            CarrierError::Zenoh(error) => matches!(error, imrs_zenoh::ZenohError::NoOwner { .. }),
        }
    }
}

impl fmt::Display for CarrierError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CarrierError::Ipc(error) => error.fmt(f),
            #[cfg(feature = "zenoh")]
            CarrierError::Zenoh(error) => error.fmt(f),
        }
    }
}

impl std::error::Error for CarrierError {}

/// Where the cell's ports cross.
#[derive(Clone)]
pub enum Carrier {
    /// iceoryx2, between the processes of this host, under the cell's name.
    Ipc(imrs_ipc::Remote),
    /// zenoh, between the hosts of the cell.
    #[cfg(feature = "zenoh")]
    Zenoh(imrs_zenoh::Host),
}

impl fmt::Debug for Carrier {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Carrier::Ipc(remote) => f.debug_tuple("Ipc").field(&remote.cell()).finish(),
            #[cfg(feature = "zenoh")]
            Carrier::Zenoh(host) => f.debug_tuple("Zenoh").field(&host.cell()).finish(),
        }
    }
}

impl Carrier {
    /// Exports `port` to the cell's other processes.
    pub async fn export<P, W>(&self, port: &P) -> Result<Exported, CarrierError>
    where
        P: Exportable<W>,
    {
        match self {
            Carrier::Ipc(remote) => imrs_ipc::export(remote, port)
                .map(Exported::Ipc)
                .map_err(CarrierError::Ipc),
            #[cfg(feature = "zenoh")]
            Carrier::Zenoh(host) => imrs_zenoh::export(host, port)
                .await
                .map(Exported::Zenoh)
                .map_err(CarrierError::Zenoh),
        }
    }

    /// Imports port `port`, owned by `owner` in another process, for `module`.
    pub async fn import<Req, Rep, U>(
        &self,
        port: &str,
        owner: &str,
        module: &str,
    ) -> Result<Imported<Req, Rep, U>, CarrierError>
    where
        Req: Crossing,
        Rep: Crossing,
        U: Importable<Req, Rep>,
    {
        match self {
            Carrier::Ipc(remote) => U::import_ipc(remote, port, owner, module),
            #[cfg(feature = "zenoh")]
            Carrier::Zenoh(host) => U::import_zenoh(host, port, owner, module).await,
        }
    }
}
