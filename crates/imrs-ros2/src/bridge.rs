//! A cell's ports as ROS 2 endpoints: a `SENDALL` port's broadcasts published on a topic,
//! a `RESPONSE` port's response handler serving a service; and the other way, a ROS 2
//! topic's messages sent to a module's `RECEIVE` port, and a module's sends on a port of
//! its own made calls of a ROS 2 service. The bridge is a user of the
//! port like any module, under a name of its own, so the port's user list, number of users
//! and TIMEOUT hold for it, and the dead-peer rule: a port closed for good ends its topic
//! (a restarted owner is waited for), and a service whose handler is gone answers with an
//! error that names the port.

use std::sync::Arc;
use std::sync::atomic::{AtomicI64, Ordering};
use std::time::Duration;

use imrs_ports::{Port, UserList, usage};
use tokio::sync::Mutex;
use tokio::task::JoinHandle;
use zenoh::query::{ConsolidationMode, QueryTarget};

use crate::attachment::Attachment;
use crate::graph::{EntityKind, Qos};
use crate::node::declare_token;
use crate::{Node, Publisher, Ros2Error, RosMessage, RosService};

/// How many messages of a subscribed topic wait for the module at most (the depth the
/// subscription's token says); more are dropped, newest first.
const SUBSCRIPTION_DEPTH: usize = 10;

/// How long a call of a ROS 2 service waits for its server's response. A sender's own wait
/// ends at its port's TIMEOUT, whichever is sooner.
const CALL_PATIENCE: Duration = Duration::from_secs(10);

/// A port bridged to ROS 2: bridged while it lives.
pub struct Bridge {
    task: Option<JoinHandle<()>>,
    /// What keeps its endpoint in zenoh and the graph: a server, a token, a subscriber.
    _keep: Box<dyn Send + Sync>,
}

impl Bridge {
    fn new(task: Option<JoinHandle<()>>, keep: impl Send + Sync + 'static) -> Self {
        Self {
            task,
            _keep: Box::new(keep),
        }
    }
}

impl Drop for Bridge {
    fn drop(&mut self) {
        if let Some(task) = &self.task {
            task.abort();
        }
    }
}

impl Node {
    /// Publishes every broadcast of `SENDALL` port `port` on ROS 2 topic `topic`, as
    /// module `module`, a user of the port. Refused, naming the port, if `module` may not
    /// use it.
    pub async fn publish_port<M, L, const N: usize>(
        &self,
        port: &Port<M, (), usage::SendAll, L, N>,
        module: &str,
        topic: &str,
    ) -> Result<Bridge, Ros2Error>
    where
        M: RosMessage,
        L: UserList,
    {
        let mut listener = port
            .user_named(module)
            .map_err(|error| Ros2Error::wiring(port.name(), error))?;
        let publisher: Publisher<M> = self.publisher(topic).await?;
        let task = tokio::spawn(async move {
            // Until the port is closed for good: then nothing more comes.
            while let Ok((message, heard)) = listener.receive().await {
                heard.reply(());
                if let Err(error) = publisher.publish(&message).await {
                    tracing::warn!(%error, "a broadcast was not published");
                }
            }
        });
        Ok(Bridge::new(Some(task), ()))
    }

    /// Serves ROS 2 service `service` with the response handler of `RESPONSE` port
    /// `port`, as module `module`, a user of the port: each request is a query of the
    /// port, answered at its owner's order. A query that fails (the port's TIMEOUT, its
    /// owner gone) is answered with an error reply that names the port and why.
    pub async fn serve_port<S, L, const N: usize>(
        &self,
        port: &Port<S::Request, S::Response, usage::Response, L, N>,
        module: &str,
        service: &str,
    ) -> Result<Bridge, Ros2Error>
    where
        S: RosService,
        L: UserList,
    {
        let asker = port
            .user_named(module)
            .map_err(|error| Ros2Error::wiring(port.name(), error))?;
        // One query of the port at a time, as one module asks.
        let asker = Arc::new(Mutex::new(asker));
        let name = port.name().to_string();
        let server = self
            .service::<S, _, _>(service, move |request| {
                let (asker, name) = (Arc::clone(&asker), name.clone());
                async move {
                    asker
                        .lock()
                        .await
                        .query(request)
                        .await
                        .map_err(|error| format!("port {name}: {error}"))
                }
            })
            .await?;
        Ok(Bridge::new(None, server))
    }

    /// Sends each message of ROS 2 topic `topic` on `RECEIVE` port `port`, as module
    /// `module`, a user of the port: its owner receives them as from any module. At most
    /// ten wait for the owner; more are dropped. A message that is not an `M` is dropped.
    pub async fn subscribe_port<M, L, const N: usize>(
        &self,
        port: &Port<M, (), usage::Receive, L, N>,
        module: &str,
        topic: &str,
    ) -> Result<Bridge, Ros2Error>
    where
        M: RosMessage,
        L: UserList,
    {
        let mut sender = port
            .user_named(module)
            .map_err(|error| Ros2Error::wiring(port.name(), error))?;
        let qos = Qos {
            reliable: true,
            depth: SUBSCRIPTION_DEPTH as u32,
        };
        let endpoint = self.endpoint(
            EntityKind::Subscription,
            topic,
            &M::dds_type_name(),
            &M::type_hash(),
            &qos,
        )?;
        let (heard, mut hearing) = tokio::sync::mpsc::channel(SUBSCRIPTION_DEPTH);
        let name = endpoint.name.clone();
        let subscriber = self
            .host()
            .session()
            .declare_subscriber(endpoint.key.clone())
            .callback(move |sample| {
                match imrs_zenoh::decode::<M>(&name, &sample.payload().to_bytes()) {
                    Ok(message) => drop(heard.try_send(message)),
                    Err(error) => tracing::debug!(%error, "a message of another shape dropped"),
                }
            })
            .await
            .map_err(|error| Ros2Error::zenoh(&endpoint.name, error))?;
        let token = declare_token(self.host(), &endpoint.token, &endpoint.name).await?;
        let task = tokio::spawn(async move {
            while let Some(message) = hearing.recv().await {
                match sender.send(message).await {
                    Ok(()) => {}
                    // The owner was late for this one: the next may be taken.
                    Err(error) if error.is_timeout() => {
                        tracing::warn!(%error, "a message of a ROS 2 topic was not taken");
                    }
                    // The port is closed for good: nothing more is taken.
                    Err(_) => break,
                }
            }
        });
        Ok(Bridge::new(Some(task), (token, subscriber)))
    }

    /// Calls ROS 2 service `service` for each request a module sends on `port`, whose
    /// owner is this bridge (the port's owner module names it in the cell): the response
    /// is the reply. A call no server answers within 10 s, or answers with an error, gets
    /// no reply: its sender's wait ends as for an owner that dropped it. One call at a
    /// time, in turn.
    pub async fn call_port<S, L, const N: usize>(
        &self,
        port: &Port<S::Request, S::Response, usage::Receive, L, N>,
        service: &str,
    ) -> Result<Bridge, Ros2Error>
    where
        S: RosService,
        L: UserList,
    {
        let mut calls = port
            .owner()
            .map_err(|error| Ros2Error::wiring(port.name(), error))?;
        let endpoint = self.endpoint(
            EntityKind::ServiceClient,
            service,
            &S::dds_type_name(),
            &S::type_hash(),
            &Qos::DEFAULT,
        )?;
        let token = declare_token(self.host(), &endpoint.token, &endpoint.name).await?;
        let session = self.host().session().clone();
        let sequence = AtomicI64::new(0);
        let task = tokio::spawn(async move {
            while let Ok((request, reply)) = calls.receive().await {
                let sequence_number = sequence.fetch_add(1, Ordering::Relaxed) + 1;
                let answer = call::<S>(&session, &endpoint, &request, sequence_number).await;
                match answer {
                    // A sender gone meanwhile is no matter: its call ended.
                    Ok(response) => drop(reply.reply(response)),
                    Err(why) => tracing::warn!(service = %endpoint.name, %why, "no response"),
                }
            }
        });
        Ok(Bridge::new(Some(task), token))
    }
}

/// One call of the service at `endpoint`: its response, or why there is none.
async fn call<S: RosService>(
    session: &zenoh::Session,
    endpoint: &crate::node::Endpoint,
    request: &S::Request,
    sequence_number: i64,
) -> Result<S::Response, String> {
    let payload = imrs_zenoh::encode(&endpoint.name, request).map_err(|e| e.to_string())?;
    let attachment = Attachment::now(sequence_number, endpoint.gid);
    let replies = session
        .get(endpoint.key.clone())
        .payload(payload)
        .attachment(attachment.to_bytes().to_vec())
        .target(QueryTarget::AllComplete)
        .consolidation(ConsolidationMode::None)
        .timeout(CALL_PATIENCE)
        .await
        .map_err(|error| error.to_string())?;
    match replies.recv_async().await {
        Ok(reply) => match reply.result() {
            Ok(sample) => imrs_zenoh::decode(&endpoint.name, &sample.payload().to_bytes())
                .map_err(|error| error.to_string()),
            Err(error) => Err(String::from_utf8_lossy(&error.payload().to_bytes()).into_owned()),
        },
        Err(_) => Err(format!("no server of {} answered", endpoint.name)),
    }
}
