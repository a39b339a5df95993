"""The cell seen by zenoh-ros2-sdk, a ROS 2 client on rmw_zenoh's conventions that is not
ours (PyPI, without ROS 2): it lists the topics and services, receives a joint state and
calls the status service and a service the cell declared itself. It computes the type
hashes itself, from the ROS 2 definitions in MESSAGES (the few it needs, as ROS 2 ships
them), so the keys it uses are its own; except std_srvs/Trigger's, whose empty request it
cannot hash: it is given the hash ROS 2 publishes for it.

Usage: ros2_sdk_client.py ENDPOINT MESSAGES
"""

import sys
import threading
import time

from zenoh_ros2_sdk import (
    ROS2ServiceClient,
    ROS2Subscriber,
    get_registry,
    get_service_names_and_types,
    get_topic_names_and_types,
)


# std_srvs/srv/Trigger's type hash, as ROS 2 publishes it (rosidl's generated description).
TRIGGER = "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"


def main():
    endpoint, messages = sys.argv[1], sys.argv[2]
    host, port = endpoint.removeprefix("tcp/").rsplit(":", 1)
    where = {"router_ip": host, "router_port": int(port)}
    get_registry(messages)

    for _ in range(50):
        topics = dict(get_topic_names_and_types(**where))
        services = dict(get_service_names_and_types(**where))
        if "/joint_states" in topics and "/status" in services:
            break
        time.sleep(0.1)
    else:
        sys.exit(f"the cell's topics and services never appeared: {topics} {services}")
    print(f"topic /joint_states {topics['/joint_states']}")
    print(f"service /status {services['/status']}")

    received = []
    got = threading.Event()

    def on_joint_state(message):
        received.append(message)
        got.set()

    subscriber = ROS2Subscriber(
        "/joint_states", "sensor_msgs/msg/JointState", on_joint_state, **where
    )
    if not got.wait(10.0):
        sys.exit("no joint state")
    state = received[0]
    print(f"joint_states {state.header.frame_id} {list(state.name)}")
    subscriber.close()

    client = ROS2ServiceClient(
        "/status",
        "std_srvs/srv/Trigger",
        request_definition="",
        response_definition="bool success\nstring message",
        type_hash=TRIGGER,
        timeout=10.0,
        **where,
    )
    response = client.call()
    if response is None:
        sys.exit("no response from /status")
    print(f"status {response.success} {response.message}")
    client.close()

    client = ROS2ServiceClient(
        "/add_two_ints", "example_interfaces/srv/AddTwoInts", timeout=10.0, **where
    )
    response = client.call(a=2, b=40)
    if response is None:
        sys.exit("no response from /add_two_ints")
    print(f"add_two_ints 2 + 40 = {response.sum}")
    client.close()


if __name__ == "__main__":
    main()
