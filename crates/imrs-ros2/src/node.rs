//! A ROS 2 node on an IMRS host: it appears in the ROS 2 graph through `rmw_zenoh`'s
//! liveliness tokens, publishes topics and serves services on `rmw_zenoh`'s key
//! expressions, in CDR with `rmw_zenoh`'s attachment.

use std::marker::PhantomData;
use std::sync::Arc;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};

use imrs_zenoh::Host;
use tokio::sync::Semaphore;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Publisher as ZenohPublisher;
use zenoh::query::{Query, Queryable};

use crate::attachment::Attachment;
use crate::graph::{EntityKind, NodeName, Qos};
use crate::{Ros2Error, RosMessage, RosService, TypeHash};

/// How many requests of one service wait for their answers at most; past them a request
/// is refused at once, so that a flood of requests grows nothing.
pub const MOST_WAITING: usize = 16;

/// Node and entity ids: unique within a zenoh session, as `rmw_zenoh` makes them (one
/// counter for the context); unique within the process here, which is as good.
static NEXT_ID: AtomicU64 = AtomicU64::new(0);

/// A ROS 2 node on `host`: seen in the graph while it lives.
pub struct Node {
    host: Host,
    name: NodeName,
    zid: String,
    id: u64,
    _token: LivelinessToken,
}

impl Node {
    /// Node `name` on `host`, announced to the graph. Call it within the tokio runtime the
    /// cell runs on.
    pub async fn new(host: &Host, name: NodeName) -> Result<Self, Ros2Error> {
        let zid = host.session().zid().to_string();
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        let token = declare_token(host, &name.node_token(&zid, id), &name.name).await?;
        Ok(Self {
            host: host.clone(),
            name,
            zid,
            id,
            _token: token,
        })
    }

    /// Where it is in the graph.
    pub fn name(&self) -> &NodeName {
        &self.name
    }

    /// The host it is on.
    pub(crate) fn host(&self) -> &Host {
        &self.host
    }

    /// An endpoint's name, key, token and GID.
    pub(crate) fn endpoint(
        &self,
        kind: EntityKind,
        name: &str,
        dds_type: &str,
        hash: &TypeHash,
        qos: &Qos,
    ) -> Result<Endpoint, Ros2Error> {
        let qualified = self.name.qualified(name)?;
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        let token = self.name.entity_token(
            &self.zid, self.id, id, kind, &qualified, dds_type, hash, qos,
        );
        Ok(Endpoint {
            key: self.name.data_key(&qualified, dds_type, hash),
            // `rmw_zenoh` makes a GID so: the XXH3-128 of the token, low half first.
            gid: xxhash_rust::xxh3::xxh3_128(token.as_bytes()).to_le_bytes(),
            token,
            name: qualified,
        })
    }

    /// A publisher of topic `topic` (relative to the node's namespace unless it starts
    /// with `/`), of messages `M`, reliable, keeping the last ten.
    pub async fn publisher<M: RosMessage>(&self, topic: &str) -> Result<Publisher<M>, Ros2Error> {
        let endpoint = self.endpoint(
            EntityKind::Publisher,
            topic,
            &M::dds_type_name(),
            &M::type_hash(),
            &Qos::DEFAULT,
        )?;
        let publisher = self
            .host
            .session()
            .declare_publisher(endpoint.key.clone())
            .await
            .map_err(|error| Ros2Error::zenoh(&endpoint.name, error))?;
        let token = declare_token(&self.host, &endpoint.token, &endpoint.name).await?;
        Ok(Publisher {
            publisher,
            gid: endpoint.gid,
            sequence: AtomicI64::new(0),
            topic: endpoint.name,
            _token: token,
            _message: PhantomData,
        })
    }

    /// A server of service `service` of type `S`: `handler` answers each request, in a
    /// task of the runtime this is called in, with a response or why there is none (sent
    /// as an error reply). A request that is not an `S::Request` is answered with an error
    /// reply that says so; past [`MOST_WAITING`] requests waiting, a request is refused
    /// at once.
    pub async fn service<S, F, Fut>(
        &self,
        service: &str,
        handler: F,
    ) -> Result<ServiceServer, Ros2Error>
    where
        S: RosService,
        F: Fn(S::Request) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = Result<S::Response, String>> + Send + 'static,
    {
        let endpoint = self.endpoint(
            EntityKind::ServiceServer,
            service,
            &S::dds_type_name(),
            &S::type_hash(),
            &Qos::DEFAULT,
        )?;
        let runtime = tokio::runtime::Handle::current();
        let handler = Arc::new(handler);
        let room = Arc::new(Semaphore::new(MOST_WAITING));
        let (name, key) = (endpoint.name.clone(), endpoint.key.clone());
        let queryable = self
            .host
            .session()
            .declare_queryable(endpoint.key.clone())
            .complete(true)
            .callback(move |query| {
                let (handler, name, key) = (Arc::clone(&handler), name.clone(), key.clone());
                match Arc::clone(&room).try_acquire_owned() {
                    Ok(place) => runtime.spawn(async move {
                        answer::<S, _, _>(&query, &name, &key, &*handler).await;
                        drop(place);
                    }),
                    Err(_) => runtime.spawn(async move {
                        let why = format!("{name}: {MOST_WAITING} requests wait already");
                        refuse(&query, why).await;
                    }),
                };
            })
            .await
            .map_err(|error| Ros2Error::zenoh(&endpoint.name, error))?;
        let token = declare_token(&self.host, &endpoint.token, &endpoint.name).await?;
        Ok(ServiceServer {
            _queryable: queryable,
            _token: token,
        })
    }
}

/// One endpoint of a node.
pub(crate) struct Endpoint {
    /// Its fully qualified name.
    pub(crate) name: String,
    /// The key expression of its data.
    pub(crate) key: String,
    /// Its liveliness token.
    pub(crate) token: String,
    pub(crate) gid: [u8; 16],
}

pub(crate) async fn declare_token(
    host: &Host,
    key: &str,
    what: &str,
) -> Result<LivelinessToken, Ros2Error> {
    host.session()
        .liveliness()
        .declare_token(key.to_owned())
        .await
        .map_err(|error| Ros2Error::zenoh(what, error))
}

/// Answers one request of service `name`: the response, on the service's own `key` as
/// `rmw_zenoh` replies, with the request's sequence number and its client's GID, as
/// `rmw_zenoh`'s client matches them.
async fn answer<S, F, Fut>(query: &Query, name: &str, key: &str, handler: &F)
where
    S: RosService,
    F: Fn(S::Request) -> Fut,
    Fut: Future<Output = Result<S::Response, String>>,
{
    let asked = query
        .attachment()
        .and_then(|attachment| Attachment::from_bytes(&attachment.to_bytes()));
    let payload = query.payload().map(|p| p.to_bytes()).unwrap_or_default();
    let (request, asked) = match (imrs_zenoh::decode::<S::Request>(name, &payload), asked) {
        (Ok(request), Some(asked)) => (request, asked),
        (Err(error), _) => return refuse(query, error.to_string()).await,
        (_, None) => {
            return refuse(
                query,
                format!("{name}: a request without rmw_zenoh's attachment"),
            )
            .await;
        }
    };
    let response = match handler(request).await {
        Ok(response) => response,
        Err(why) => return refuse(query, why).await,
    };
    let sent = match imrs_zenoh::encode(name, &response) {
        Ok(bytes) => {
            let attachment = Attachment::now(asked.sequence_number, asked.source_gid);
            query
                .reply(key.to_owned(), bytes)
                .attachment(attachment.to_bytes().to_vec())
                .await
        }
        Err(error) => query.reply_err(error.to_string()).await,
    };
    if let Err(error) = sent {
        tracing::debug!(%error, "a response could not be sent: its client is gone");
    }
}

async fn refuse(query: &Query, why: String) {
    if let Err(error) = query.reply_err(why).await {
        tracing::debug!(%error, "a refusal could not be sent: its client is gone");
    }
}

/// A publisher of a topic: seen in the graph while it lives.
pub struct Publisher<M> {
    publisher: ZenohPublisher<'static>,
    gid: [u8; 16],
    sequence: AtomicI64,
    topic: String,
    _token: LivelinessToken,
    _message: PhantomData<fn(M)>,
}

impl<M: RosMessage> Publisher<M> {
    /// Publishes `message` to every subscription of the topic.
    pub async fn publish(&self, message: &M) -> Result<(), Ros2Error> {
        let bytes = imrs_zenoh::encode(&self.topic, message)
            .map_err(|error| Ros2Error::zenoh(&self.topic, error))?;
        let sequence = self.sequence.fetch_add(1, Ordering::Relaxed) + 1;
        self.publisher
            .put(bytes)
            .attachment(Attachment::now(sequence, self.gid).to_bytes().to_vec())
            .await
            .map_err(|error| Ros2Error::zenoh(&self.topic, error))
    }

    /// Its topic, fully qualified.
    pub fn topic(&self) -> &str {
        &self.topic
    }
}

/// A service's server: serves, and is seen in the graph, while it lives.
pub struct ServiceServer {
    _queryable: Queryable<()>,
    _token: LivelinessToken,
}
