//! How a remote module's request goes into the real port on the owner's host: through that
//! module's own end, with the primitive its usage gives it.

use std::time::Duration;

use imrs_ports::{End, usage};

/// A remote module's end of the real port, through which its requests go in.
pub(crate) trait Forward<Req, Rep>: Send + 'static {
    /// The request, as the module's primitive on this port: its reply, or why there is
    /// none (the port's own error, naming it).
    fn forward(&mut self, request: Req) -> impl Future<Output = Result<Rep, String>> + Send + '_;

    /// The port's TIMEOUT for this module, if it has one.
    fn timeout(&self) -> Option<Duration>;

    /// The same end, its TIMEOUT (if any) longer by `by`. The module's own host times its
    /// wait to the port's TIMEOUT; this end's bound is a backstop, longer by a lease, so
    /// that the module hears its own `ReplyTimeout` rather than a `NoReply` racing it.
    fn waiting_longer(self, by: Duration) -> Self;
}

/// The module's end, whose primitive is `$primitive` (a send; a query, answered by the
/// owner's response handler when the owner's order says).
macro_rules! forwards {
    ($usage:ty, $primitive:ident) => {
        impl<Req: Send + 'static, Rep: Send + 'static> Forward<Req, Rep> for End<Req, Rep, $usage> {
            async fn forward(&mut self, request: Req) -> Result<Rep, String> {
                self.$primitive(request)
                    .await
                    .map_err(|error| error.to_string())
            }

            fn timeout(&self) -> Option<Duration> {
                End::timeout(self)
            }

            fn waiting_longer(self, by: Duration) -> Self {
                match End::timeout(&self) {
                    Some(timeout) => self.with_timeout(timeout + by),
                    None => self,
                }
            }
        }
    };
}

forwards!(usage::Send, send);
forwards!(usage::Query, query);
