//! A ROS 2 service type: a request and a response message, and the type hash of the pair.

use std::collections::BTreeMap;

use crate::message::dds_type_name;
use crate::msgs::service_msgs::ServiceEventInfo;
use crate::{Field, FieldType, RosField, RosMessage, TypeDescription, TypeHash};

/// A ROS 2 service type, `package/srv/Name`: its request is `package/srv/Name_Request`,
/// its response `package/srv/Name_Response`. Declare one with
/// [`ros_service!`](crate::ros_service).
pub trait RosService: Send + Sync + 'static {
    /// Its ROS name, `package/srv/Name`.
    const TYPE_NAME: &'static str;
    /// What a client asks.
    type Request: RosMessage;
    /// What the server answers.
    type Response: RosMessage;

    /// Its RIHS01 type hash, as ROS 2 computes it: that of a type whose fields are the
    /// request, the response and the service's event message (`Name_Event`, which
    /// `service_msgs` describes), with every type they refer to.
    fn type_hash() -> TypeHash {
        let (request, response) = (Self::Request::TYPE_NAME, Self::Response::TYPE_NAME);
        let event = format!("{}_Event", Self::TYPE_NAME);
        let one_of = |type_name: &str| FieldType {
            type_id: FieldType::NESTED_TYPE + FieldType::BOUNDED_SEQUENCE,
            capacity: 1,
            ..FieldType::nested(type_name)
        };
        let mut referenced = BTreeMap::new();
        <Self::Request as RosField>::referenced(&mut referenced);
        <Self::Response as RosField>::referenced(&mut referenced);
        <ServiceEventInfo as RosField>::referenced(&mut referenced);
        referenced.insert(
            event.clone(),
            vec![
                Field::new("info", ServiceEventInfo::field_type()),
                Field::new("request", one_of(request)),
                Field::new("response", one_of(response)),
            ],
        );
        TypeDescription {
            type_name: Self::TYPE_NAME.to_owned(),
            fields: vec![
                Field::new("request_message", FieldType::nested(request)),
                Field::new("response_message", FieldType::nested(response)),
                Field::new("event_message", FieldType::nested(&event)),
            ],
        }
        .hash(&referenced)
    }

    /// The name `rmw_zenoh` gives it in a key expression: `package::srv::dds_::Name_`.
    fn dds_type_name() -> String {
        dds_type_name(Self::TYPE_NAME)
    }
}

/// Whether `service`'s request or response is named `part`: `service` then `_Request` or
/// `_Response`. Checked when a service is declared, at compile time.
pub const fn is_part_of(part: &str, service: &str, suffix: &str) -> bool {
    let (part, service, suffix) = (part.as_bytes(), service.as_bytes(), suffix.as_bytes());
    if part.len() != service.len() + suffix.len() {
        return false;
    }
    let mut at = 0;
    while at < part.len() {
        let expected = if at < service.len() {
            service[at]
        } else {
            suffix[at - service.len()]
        };
        if part[at] != expected {
            return false;
        }
        at += 1;
    }
    true
}

/// Declares a ROS 2 service type: a unit struct with its ROS name, its request and its
/// response messages (declared with [`ros_message!`](crate::ros_message) as
/// `package/srv/Name_Request` and `package/srv/Name_Response`, which is checked at compile
/// time).
///
/// ```
/// use imrs_ros2::{ros_message, ros_service};
///
/// ros_message! {
///     pub struct ParkRequest = "cell_srvs/srv/Park_Request" { pub robot: String }
/// }
/// ros_message! {
///     pub struct ParkResponse = "cell_srvs/srv/Park_Response" { pub parked: bool }
/// }
/// ros_service! {
///     /// Parks a robot.
///     pub service Park = "cell_srvs/srv/Park" {
///         request: ParkRequest,
///         response: ParkResponse,
///     }
/// }
/// ```
///
/// A request or response named for another service does not compile:
///
/// ```compile_fail,E0080
/// use imrs_ros2::msgs::std_srvs::{TriggerRequest, TriggerResponse};
///
/// imrs_ros2::ros_service! {
///     pub service Park = "cell_srvs/srv/Park" {
///         request: TriggerRequest,
///         response: TriggerResponse,
///     }
/// }
/// ```
#[macro_export]
macro_rules! ros_service {
    (
        $(#[$meta:meta])*
        $vis:vis service $name:ident = $ros_name:literal {
            request: $request:ty,
            response: $response:ty $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
        $vis struct $name;

        const _: () = {
            assert!(
                $crate::is_interface_name($ros_name, "srv"),
                concat!("not a ROS 2 service name (package/srv/Name): ", $ros_name)
            );
            assert!(
                $crate::is_part_of(
                    <$request as $crate::RosMessage>::TYPE_NAME,
                    $ros_name,
                    "_Request"
                ),
                concat!("the request of ", $ros_name, " must be named ", $ros_name, "_Request")
            );
            assert!(
                $crate::is_part_of(
                    <$response as $crate::RosMessage>::TYPE_NAME,
                    $ros_name,
                    "_Response"
                ),
                concat!("the response of ", $ros_name, " must be named ", $ros_name, "_Response")
            );
        };

        impl $crate::RosService for $name {
            const TYPE_NAME: &'static str = $ros_name;
            type Request = $request;
            type Response = $response;
        }
    };
}
