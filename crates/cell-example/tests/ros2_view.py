"""The chip cell seen from ROS 2 by zenoh-ros2-sdk (PyPI), as a ROS 2 user would look at it:
lists its topics and services, reads the robots' joints, waits for an alarm, and asks its
status.

Usage: ros2_view.py ENDPOINT MESSAGES
"""

import os
import queue
import sys
import time
import traceback

from zenoh_ros2_sdk import (
    ROS2ServiceClient,
    ROS2Subscriber,
    get_registry,
    get_service_names_and_types,
    get_topic_names_and_types,
)

# std_srvs/srv/Trigger's type hash, as ROS 2 publishes it: the SDK cannot hash a service
# whose request is empty.
TRIGGER = "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"


def main():
    endpoint, messages = sys.argv[1], sys.argv[2]
    host, port = endpoint.removeprefix("tcp/").rsplit(":", 1)
    where = {"router_ip": host, "router_port": int(port)}
    get_registry(messages)
    # Listening first: an alarm raised before anyone listens is not kept (volatile).
    joints, alarms = queue.Queue(), queue.Queue()
    watching = [
        ROS2Subscriber("/alarms", "std_msgs/msg/String", alarms.put, **where),
        ROS2Subscriber("/joint_states", "sensor_msgs/msg/JointState", joints.put, **where),
    ]

    for _ in range(100):
        topics = dict(get_topic_names_and_types(**where))
        services = dict(get_service_names_and_types(**where))
        if {"/joint_states", "/alarms"} <= topics.keys() and "/status" in services:
            break
        time.sleep(0.1)
    else:
        sys.exit(f"the cell never appeared: {topics} {services}")
    for name in ("/alarms", "/joint_states"):
        print(f"topic {name} {topics[name]}")
    print(f"service /status {services['/status']}")

    state = joints.get(timeout=10.0)
    print(f"joints {len(state.name)} {sorted(state.name)[:2]}")
    alarm = alarms.get(timeout=20.0)
    print(f"alarm {alarm.data}")
    for subscriber in watching:
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


if __name__ == "__main__":
    # A session left open can hold the interpreter at its exit: leave at once either way.
    try:
        main()
    except BaseException:
        traceback.print_exc()
        sys.stdout.flush()
        os._exit(1)
    sys.stdout.flush()
    os._exit(0)
