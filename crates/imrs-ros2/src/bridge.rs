//! A cell's ports as ROS 2 endpoints: a `SENDALL` port's broadcasts published on a topic,
//! a `RESPONSE` port's response handler serving a service. The bridge is a user of the
//! port like any module, under a name of its own, so the port's user list, number of users
//! and TIMEOUT hold for it, and the dead-peer rule: a port whose owner is gone ends its
//! topic, and a service whose handler is gone answers with an error that names the port.

use std::sync::Arc;

use imrs_ports::{Port, UserList, usage};
use tokio::sync::Mutex;
use tokio::task::JoinHandle;

use crate::{Node, Publisher, Ros2Error, RosMessage, RosService, ServiceServer};

/// A port bridged to ROS 2: bridged while it lives.
pub struct Bridge {
    task: Option<JoinHandle<()>>,
    _server: Option<ServiceServer>,
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
            // Until the port's owner is gone for good: then nothing more comes.
            while let Ok((message, heard)) = listener.receive().await {
                heard.reply(());
                if let Err(error) = publisher.publish(&message).await {
                    tracing::warn!(%error, "a broadcast was not published");
                }
            }
        });
        Ok(Bridge {
            task: Some(task),
            _server: None,
        })
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
        Ok(Bridge {
            task: None,
            _server: Some(server),
        })
    }
}
