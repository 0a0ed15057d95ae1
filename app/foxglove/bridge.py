"""``FoxgloveBridge``: the live ROS graph served over the Foxglove WebSocket protocol.

The server is foxglove-sdk's (``foxglove.start_server``); this class feeds it.
Clients reach it through ``ProtocolRelay`` (app/foxglove/relay.py), which also
accepts the protocol's older name that Lichtblick offers.
Each topic someone publishes becomes a channel: encoding ``cdr`` (the bytes a
ROS 2 subscriber receives, passed through unparsed) and schema encoding
``ros2msg`` (the full definition, nested types after ``====`` lines, as a
rosbag2 file stores it). A channel costs a ROS subscription only while at
least one client subscribes to it. A client may publish ("clientPublish") on
topics it advertised with a ROS message type this machine knows: each message
is checked by deserializing it and published on ROS, so Foxglove's teleop
drives the robot through ``/cmd_vel``. Whatever a client sends beyond that, or
beyond ``BridgeLimits``, is refused, and said to the clients as a status.

Each ROS service on the graph (not the parameter and type-description services
every node has, nor hidden ones) is advertised as a Foxglove service: request
and response schemas are ``ros2msg`` texts, payloads ``cdr``. A call's request
is checked by deserializing it, then sent to the ROS service; its CDR response
goes back to the client, or a failure after ``call_timeout_sec``.

Parameters are named as Foxglove's ROS 2 bridge names them,
``/node_name.param_name``. The SDK asks for them synchronously, on a
client's socket thread, so the answer comes from a cache: the bridge's thread
reads the nodes' parameters through their services (asynchronously, bounded,
again every ``parameter_refresh_sec`` and soon after a client asks; nothing is
read before a client first asks). A set is
queued for the bridge's thread; the values first returned are the known ones,
and the new ones follow to subscribed clients once the node accepted them (a
refusal is said as a status).

Three kinds of threads meet here, and only one of them touches ROS or the
server's channels:

- the server's threads (Rust) call the listener when a client subscribes,
  advertises or sends. The listener records what was asked, under a short
  lock, and wakes the bridge's thread. It calls nothing: closing a channel
  calls the listener back on the closing thread, and creating ROS entities
  there would hold up every client's socket.
- the bridge's thread reads the graph, opens and closes channels, creates
  and destroys subscriptions and publishers, and publishes what clients sent.
- the ROS executor's thread (the dashboard's) runs the subscriptions'
  callbacks: each hands its bytes and receive time to the channel, where the
  server queues them per client (dropping the oldest for a client that reads
  too slowly), and returns. It also completes service calls' futures.

A service call is the one place where a server's thread waits: the SDK runs
a Python handler on its blocking pool (not on a client's socket) and sends
what it returns. The handler queues the call for the bridge's thread, which
makes the rclpy client and calls ``call_async``; the future's callback wakes
the handler. Calls in flight are bounded per client and in all, and each
waits at most ``call_timeout_sec``.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import foxglove
import foxglove.channel
import psutil
from foxglove.websocket import (
    Capability,
    ChannelView,
    Client,
    ClientChannel,
    MessageSchema,
    Parameter,
    ParameterType,
    ServerListener,
    Service,
    ServiceRequest,
    ServiceSchema,
    StatusLevel,
    WebSocketServer,
)
from rcl_interfaces.msg import Parameter as RosParameter
from rcl_interfaces.msg import ParameterType as RosParameterType
from rcl_interfaces.srv import GetParameters, ListParameters, SetParameters
from rclpy.client import Client as RosClient
from rclpy.exceptions import InvalidTopicNameException
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message, serialize_message
from rclpy.subscription import Subscription
from rclpy.validate_full_topic_name import validate_full_topic_name

from app.bags.definitions import definition, service_definitions
from app.bags.errors import BagError
from app.foxglove.assets import fetch_asset
from app.foxglove.limits import BridgeLimits, NoteThrottle, RateLimit, ros_message_type
from app.foxglove.relay import ProtocolRelay
from app.ros.convert import ConversionError, import_type
from app.ros.names import ACTION_MARKER, QUIET_TOPICS, is_hidden_node, is_internal_topic, node_fqn
from app.ros.params import parameter_value, python_value
from app.ros.qos import matching_qos

if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Protocol

    from foxglove import AnyNativeParameterValue
    from rclpy.task import Future

    class _ServiceType(Protocol):
        """A generated service class: its request (and response) message classes."""

        Request: type
        Response: type


log = logging.getLogger(__name__)

SERVER_NAME = "ROS 2 Classroom"
ENCODING = "cdr"  # ROS 2's serialized messages, as a subscriber receives them
SCHEMA_ENCODING = "ros2msg"
SUBSCRIPTION_DEPTH = 10
PUBLISH_QOS = QoSProfile(depth=10)  # reliable and volatile, as `ros2 topic pub` publishes
RECENT_NOTES = 64
TOPIC_NAME_MAX = 256
JOIN_SEC = 5.0
# Every node offers these (parameters, type descriptions): listing them per node is noise.
QUIET_SERVICE_PACKAGES = ("rcl_interfaces/srv/", "type_description_interfaces/srv/")
CALL_POLL_SEC = 0.05  # how often a call waits for its server to be discovered
ASKED_REREAD_SEC = 1.0  # a client asking for parameters re-reads a node at most this often

ClientKey = tuple[int, int]  # (client id, the client's channel id)


@dataclass
class _Topic:
    """A topic served as a channel (the bridge's thread only)."""

    name: str
    msgtype: str
    py_type: type  # the generated message class
    channel: foxglove.Channel
    subscription: Subscription | None = None
    gone_since: float | None = None


@dataclass
class _Advert:
    """A channel a client advertised for publishing: pending until the bridge's thread decides."""

    key: ClientKey
    topic: str
    encoding: str
    schema_name: str
    rate: RateLimit
    accepted: bool = False
    msgtype: str = ""


@dataclass
class _Publisher:
    """One ROS publisher per topic, shared by every client channel that publishes on it."""

    publisher: Publisher
    py_type: type  # the generated message class
    msgtype: str
    users: set[ClientKey] = field(default_factory=set)


@dataclass
class _Service:
    """A ROS service advertised to clients (the bridge's thread only)."""

    name: str
    srvtype: str
    py_type: _ServiceType
    client: RosClient | None = None  # made on its first call
    gone_since: float | None = None


@dataclass(eq=False)  # one call is itself, whatever its fields hold
class _Call:
    """One client's service call, from the handler to the bridge's thread and back."""

    client: int
    service: str
    payload: bytes
    deadline: float  # time.monotonic()
    done: threading.Event = field(default_factory=threading.Event)
    response: bytes | None = None
    error: str = ""
    over: bool = False  # its handler returned: nobody waits any more (under the lock)
    request: object = None  # deserialized, waiting for its server (the bridge's thread only)
    future: Future | None = None  # rclpy's, once sent (the bridge's thread only)


@dataclass
class _ParamSet:
    """Parameters to set on one node: waiting for its server, then for its answer."""

    request: SetParameters.Request
    started: float
    future: Future | None = None


@dataclass
class _ParamNode:
    """A node whose parameters are cached (the bridge's thread only)."""

    fqn: str
    list_client: RosClient
    get_client: RosClient
    set_client: RosClient | None = None
    stage: str = ""  # "list" or "get" while a read is on its way
    future: Any = None
    names: list[str] = field(default_factory=list)
    started: float = 0.0
    read_at: float | None = None  # when its values last came
    setting: list[_ParamSet] = field(default_factory=list)


@dataclass
class BridgeCounts:
    """What went through, and what was refused (a snapshot)."""

    channels: int
    subscriptions: int
    publishers: int
    forwarded: int
    published: int
    refused: int
    dropped: int
    services: int = 0
    calls: int = 0  # answered by ROS and sent back


class FoxgloveBridge:
    """The graph of ``node`` served at ``ws://host:port`` until ``close``.

    ``node`` is spun by someone else (the dashboard's executor); ``port`` 0
    picks a free one (read ``port`` after ``start``).
    """

    def __init__(
        self,
        node: Node,
        host: str = "127.0.0.1",
        port: int = 8765,
        limits: BridgeLimits | None = None,
    ) -> None:
        self._node = node
        self.host = host
        self._asked_port = port
        self._port = port
        self.limits = limits or BridgeLimits()
        # Our own context: our channels reach only our server (not an MCAP file or another
        # server that uses the SDK's global one).
        self._context = foxglove.Context()
        self._server: WebSocketServer | None = None
        self._relay: ProtocolRelay | None = None  # the public port, in front of the server
        self._sdk_port = 0
        self._stopping = threading.Event()
        self._wake = threading.Event()
        self._thread = threading.Thread(target=self._run, name="foxglove-bridge", daemon=True)
        # Written by the server's threads, read by the bridge's thread: under _lock.
        self._lock = threading.Lock()
        self._watchers: dict[int, set[int]] = {}  # channel id -> ids of subscribed clients
        self._adverts: dict[ClientKey, _Advert] = {}  # pending or accepted, never refused
        self._released: list[_Advert] = []  # accepted, then unadvertised: to let go
        self._inbox: deque[tuple[ClientKey, bytes]] = deque()
        self._notes: deque[str] = deque(maxlen=RECENT_NOTES)  # to say to the clients
        self._recent: deque[str] = deque(maxlen=RECENT_NOTES)  # said, newest last
        self._throttle = NoteThrottle(self.limits.repeat_note_sec)
        self._refused = 0
        self._dropped = 0
        self._calls: list[_Call] = []  # waiting for an answer (the handlers hold them)
        self._new_calls: list[_Call] = []  # for the bridge's thread to send
        self._answered = 0
        # "/node.param" -> (ROS ParameterType, plain value): replaced whole by the bridge's thread.
        self._param_cache: dict[str, tuple[int, object]] = {}
        self._param_sets: deque[tuple[str, AnyNativeParameterValue | None]] = deque()
        self._params_asked = False
        # The executor's thread only.
        self._forwarded = 0
        # The bridge's thread only.
        self._topics: dict[str, _Topic] = {}
        self._publishers: dict[str, _Publisher] = {}
        self._published = 0
        self._unusable: set[tuple[str, str]] = set()  # (topic, type) we cannot serve
        self._shape = (0, 0, 0)  # channels, subscriptions, publishers: replaced whole
        self._clients: set[int] = set()  # ids of the clients seen (watching or publishing)
        self._services: dict[str, _Service] = {}
        self._sent: list[_Call] = []  # calls on their way, or waiting for their server
        self._param_nodes: dict[str, _ParamNode] = {}
        self._nodes_read_at = 0.0
        self._params_wanted = False  # a client has asked for or set parameters

    # ------------------------------------------------------------------ lifecycle

    def start(self) -> None:
        """Listen (FoxgloveError, a RuntimeError, when the port is taken) and serve."""
        # The SDK's server on a loopback port of its own; clients come through the relay
        # on the address asked for, which also takes Lichtblick's name of the protocol.
        self._server = foxglove.start_server(
            name=SERVER_NAME,
            host="127.0.0.1",
            port=0,
            capabilities=[Capability.ClientPublish, Capability.Services, Capability.Parameters],
            asset_handler=fetch_asset,  # a URDF's package:// meshes for the 3D panel ("assets")
            supported_encodings=[ENCODING],
            server_listener=_Listener(self),
            context=self._context,
            message_backlog_size=self.limits.client_backlog,
        )
        self._sdk_port = self._server.port
        relay = ProtocolRelay(self.host, self._asked_port, self._sdk_port)
        try:
            relay.start()
        except BaseException:
            self._server.stop()
            self._server = None
            raise
        self._relay = relay
        self._port = relay.port  # the one it got (``port`` 0: a free one)
        self._thread.start()

    @property
    def port(self) -> int:
        return self._port

    @property
    def url(self) -> str:
        """What to type into Foxglove's "Open connection" (Foxglove WebSocket)."""
        return f"ws://{self.host}:{self.port}"

    def close(self) -> None:
        """Clients first (their subscriptions end), then our thread, then ROS entities."""
        if self._server is None or self._stopping.is_set():
            return
        self._stopping.set()
        self._wake.set()
        self._fail_all_calls("the bridge is closing")  # their handlers return now
        if self._relay is not None:
            self._relay.stop()
        self._server.stop()
        if self._thread.is_alive():
            self._thread.join(JOIN_SEC)
        if self._thread.is_alive():
            # It owns the ROS entities: leave them to the node's destruction.
            log.error("foxglove bridge: its thread did not end within %.0f s", JOIN_SEC)
            return
        for topic in list(self._topics.values()):
            self._close_topic(topic)
        for name in list(self._publishers):
            self._drop_publisher(name)
        for service in list(self._services.values()):
            self._close_service(service, advertised=False)  # the server is gone
        for fqn in list(self._param_nodes):
            self._forget_param_node(fqn)
        self._shape = (0, 0, 0)

    def counts(self) -> BridgeCounts:
        with self._lock:
            refused, dropped = self._refused, self._dropped
        channels, subscriptions, publishers = self._shape
        return BridgeCounts(
            channels=channels,
            subscriptions=subscriptions,
            publishers=publishers,
            forwarded=self._forwarded,
            published=self._published,
            refused=refused,
            dropped=dropped,
            services=len(self._services),
            calls=self._answered,
        )

    def recent_notes(self) -> list[str]:
        """The refusals and warnings said to clients lately, oldest first."""
        with self._lock:
            return list(self._recent)

    # ------------------------------------------------- called by the server's threads

    def _on_watch(self, client: int, channel: int, watching: bool) -> None:
        with self._lock:
            clients = self._watchers.setdefault(channel, set())
            if watching:
                clients.add(client)
            else:
                clients.discard(client)
                if not clients:
                    del self._watchers[channel]
        self._wake.set()

    def _on_advertise(self, client: int, channel: ClientChannel) -> None:
        key = (client, channel.id)
        topic, schema = str(channel.topic), str(channel.schema_name)
        with self._lock:
            mine = sum(1 for k in self._adverts if k[0] == client)
            if mine >= self.limits.max_client_channels:
                self._refuse_locked(
                    f"refused to publish on {_short(topic)}: a client may advertise at most "
                    f"{self.limits.max_client_channels} channels"
                )
                return
            self._adverts[key] = _Advert(
                key,
                topic,
                str(channel.encoding),
                schema,
                RateLimit(self.limits.publish_rate_hz, self.limits.publish_burst),
            )
        self._wake.set()

    def _on_unadvertise(self, client: int, channel: int) -> None:
        with self._lock:
            advert = self._adverts.pop((client, channel), None)
            if advert is not None and advert.accepted:
                self._released.append(advert)
        self._wake.set()

    def _on_message(self, client: int, channel: int, data: bytes) -> None:
        with self._lock:
            advert = self._adverts.get((client, channel))
            if advert is None:
                self._refuse_locked(
                    f"refused a message on client channel {channel}: it was not accepted "
                    "for publishing (see the earlier status)"
                )
                return
            if len(data) > self.limits.max_client_message_bytes:
                self._refuse_locked(
                    f"refused a {len(data)}-byte message on {_short(advert.topic)}: at most "
                    f"{self.limits.max_client_message_bytes} bytes"
                )
                return
            if not advert.rate.allow():
                self._dropped += 1
                self._note_locked(
                    f"dropping messages on {_short(advert.topic)}: at most "
                    f"{self.limits.publish_rate_hz:g} a second"
                )
                return
            if len(self._inbox) >= self.limits.pending_messages:
                self._inbox.popleft()
                self._dropped += 1
            self._inbox.append(((client, channel), data))
        self._wake.set()

    def _on_call(self, request: ServiceRequest) -> bytes:
        """A service call, on the server's blocking pool: queue it, wait for the answer.

        What it raises goes back to the client as the call's failure.
        """
        name, client = str(request.service_name), int(request.client_id)
        payload = bytes(request.payload)
        limits = self.limits
        if len(payload) > limits.max_request_bytes:
            self._note(f"refused a {len(payload)}-byte request to {_short(name)}")
            raise ValueError(f"a request may be at most {limits.max_request_bytes} bytes")
        with self._lock:
            if self._stopping.is_set():
                raise RuntimeError("the bridge is closing")
            mine = sum(1 for c in self._calls if c.client == client)
            if mine >= limits.calls_per_client or len(self._calls) >= limits.max_calls:
                self._refuse_locked(f"refused a call to {_short(name)}: too many calls at once")
                raise RuntimeError(
                    f"too many calls at once (at most {limits.calls_per_client} per client, "
                    f"{limits.max_calls} in all): wait for the answers"
                )
            call = _Call(client, name, payload, time.monotonic() + limits.call_timeout_sec)
            self._calls.append(call)
            self._new_calls.append(call)
        self._wake.set()
        try:
            if not call.done.wait(limits.call_timeout_sec + 1.0):
                raise TimeoutError(f"{name} did not answer within {limits.call_timeout_sec:g} s")
            if call.response is None:
                raise RuntimeError(call.error or f"{name} gave no answer")
            return call.response
        finally:
            with self._lock:
                call.over = True  # the bridge's thread lets go of it
                if call in self._calls:
                    self._calls.remove(call)
            self._wake.set()

    def _on_get_parameters(self, names: list[str]) -> list[Parameter]:
        """From the cache (the SDK waits for the answer on a client's socket thread)."""
        with self._lock:
            cache = self._param_cache
            self._params_asked = True  # read them again soon
        self._wake.set()
        wanted = names or sorted(cache)
        return [_foxglove_parameter(n, *cache[n]) for n in wanted if n in cache]

    def _on_set_parameters(self, parameters: list[Parameter]) -> list[Parameter]:
        """Queued for the bridge's thread; answered with the values known so far."""
        with self._lock:
            for parameter in parameters:
                if len(self._param_sets) >= self.limits.pending_parameter_sets:
                    self._refuse_locked("refused a parameter set: too many waiting")
                    break
                self._param_sets.append((str(parameter.name), parameter.get_value()))
            cache = self._param_cache
        self._wake.set()
        return [_foxglove_parameter(p.name, *cache[p.name]) for p in parameters if p.name in cache]

    def _fail_all_calls(self, why: str) -> None:
        with self._lock:
            calls = list(self._calls)
        for call in calls:
            self._finish(call, error=why)

    def _refuse_locked(self, text: str) -> None:
        self._refused += 1
        self._note_locked(text)

    def _note_locked(self, text: str) -> None:
        if self._throttle.due(text):
            self._notes.append(text)

    def _note(self, text: str, *, refusal: bool = True) -> None:
        with self._lock:
            if refusal:
                self._refused += 1
            self._note_locked(text)

    # ----------------------------------------------------------- the bridge's thread

    def _run(self) -> None:
        next_read = 0.0
        while not self._stopping.is_set():
            if time.monotonic() >= next_read:
                self._step(self._read_graph)
                self._step(self._read_services)
                next_read = time.monotonic() + self.limits.refresh_sec
            self._step(self._greet_clients)
            self._step(self._settle_adverts)
            self._step(self._settle_subscriptions)
            self._step(self._publish_inbox)
            self._step(self._send_calls)
            self._step(self._settle_parameters)
            self._step(self._say_notes)
            self._shape = (
                len(self._topics),
                sum(1 for t in self._topics.values() if t.subscription is not None),
                len(self._publishers),
            )
            wait = max(0.0, next_read - time.monotonic())
            if any(c.future is None for c in self._sent) or any(
                n.stage or n.setting for n in self._param_nodes.values()
            ):
                wait = min(wait, CALL_POLL_SEC)  # a call waits for its server to be discovered
            self._wake.wait(wait)
            self._wake.clear()  # what woke us is state, read again on the next round

    def _step(self, work: Callable[[], None]) -> None:
        try:
            work()
        except Exception:  # one failed round must not end the bridge
            log.exception("foxglove bridge: %s failed", work.__name__)

    def _greet_clients(self) -> None:
        with self._lock:
            clients = {c for watching in self._watchers.values() for c in watching}
            clients |= {client for client, _channel in self._adverts}
        if clients - self._clients:
            no_delay(self._sdk_port)
        self._clients = clients

    def _read_graph(self) -> None:
        now = time.monotonic()
        live: dict[str, str] = {}
        for name, types in self._node.get_topic_names_and_types():
            if is_internal_topic(name) or self._node.count_publishers(name) == 0:
                continue
            if len(types) != 1:
                self._unusable_note(name, "+".join(types), "it carries several types at once")
                continue
            live[name] = types[0]
        for topic in list(self._topics.values()):
            msgtype = live.get(topic.name)
            if msgtype == topic.msgtype:
                topic.gone_since = None
            elif msgtype is not None:
                self._close_topic(topic)  # now of another type: opened again below
            elif topic.gone_since is None:
                topic.gone_since = now  # a publisher restarting is not a topic gone
            elif now - topic.gone_since >= self.limits.gone_after_sec:
                self._close_topic(topic)
        for name, msgtype in sorted(live.items()):
            if name in self._topics:
                continue
            if len(self._topics) >= self.limits.max_channels:
                self._note(
                    f"serving only {self.limits.max_channels} of {len(live)} topics",
                    refusal=False,
                )
                break
            self._open_topic(name, msgtype)

    def _unusable_note(self, name: str, msgtype: str, why: str) -> None:
        if (name, msgtype) in self._unusable:
            return
        if len(self._unusable) > 4 * self.limits.max_channels:
            self._unusable.clear()  # bounded: a graph that churns types is told again
        self._unusable.add((name, msgtype))
        self._note(f"not serving {_short(name)}: {why}", refusal=False)

    def _open_topic(self, name: str, msgtype: str) -> None:
        if (name, msgtype) in self._unusable:
            return
        try:
            py_type = import_type(msgtype, "msg")
            text, _digest = definition(msgtype)
        except (ConversionError, BagError) as exc:
            self._unusable_note(name, msgtype, str(exc))
            return
        schema = foxglove.Schema(name=msgtype, encoding=SCHEMA_ENCODING, data=text.encode())
        channel = foxglove.Channel(
            name, schema=schema, message_encoding=ENCODING, context=self._context
        )
        self._topics[name] = _Topic(name, msgtype, py_type, channel)

    def _close_topic(self, topic: _Topic) -> None:
        if topic.subscription is not None:
            self._node.destroy_subscription(topic.subscription)
            topic.subscription = None
        del self._topics[topic.name]
        channel_id = topic.channel.id()
        topic.channel.close()  # unadvertised; subscribed clients' on_unsubscribe runs here
        # foxglove.Channel keeps every channel it made in a module registry (for
        # foxglove.log), closed ones too: hours of topics coming and going would grow it.
        foxglove.channel._channels_by_id.pop(channel_id, None)

    def _settle_subscriptions(self) -> None:
        with self._lock:
            watched = {channel for channel, clients in self._watchers.items() if clients}
        active = sum(1 for t in self._topics.values() if t.subscription is not None)
        for topic in list(self._topics.values()):
            wanted = topic.channel.id() in watched
            if wanted and topic.subscription is None:
                if active >= self.limits.max_subscriptions:
                    self._note(
                        f"not subscribing to {_short(topic.name)}: at most "
                        f"{self.limits.max_subscriptions} topics at once",
                        refusal=False,  # asked again each round while it stands
                    )
                    continue
                topic.subscription = self._subscribe(topic)
                active += 1
            elif not wanted and topic.subscription is not None:
                self._node.destroy_subscription(topic.subscription)
                topic.subscription = None
                active -= 1

    def _subscribe(self, topic: _Topic) -> Subscription:
        log_message = topic.channel.log
        limit = self.limits.max_forward_bytes

        def forward(data: bytes, info: dict[str, int]) -> None:
            # The executor's thread: hand over and return. The time is when the middleware
            # received the message, as a bag records it.
            if len(data) > limit:
                return
            log_message(data, log_time=info.get("received_timestamp") or time.time_ns())
            self._forwarded += 1

        return self._node.create_subscription(
            topic.py_type,
            topic.name,
            forward,  # type: ignore[arg-type]  # rclpy passes (message, info) to two parameters
            matching_qos(self._node, topic.name, depth=SUBSCRIPTION_DEPTH),
            raw=True,
        )

    def _settle_adverts(self) -> None:
        with self._lock:
            pending = [a for a in self._adverts.values() if not a.accepted]
            released, self._released = self._released, []
        for advert in released:
            self._let_go(advert)
        for advert in pending:
            try:
                reason = self._refusal(advert)
            except Exception as exc:  # rclpy refused to make the publisher: refuse the client
                log.exception("foxglove bridge: publishing on %s", advert.topic)
                reason = f"refused to publish on {_short(advert.topic)}: {exc}"
            if reason is None:
                self._publishers[advert.topic].users.add(advert.key)
            with self._lock:
                still = self._adverts.get(advert.key) is advert
                if still and reason is None:
                    advert.accepted = True
                elif still:
                    del self._adverts[advert.key]
                    self._refuse_locked(reason or "")
            if reason is None and not still:
                self._let_go(advert)  # unadvertised while we decided

    def _refusal(self, advert: _Advert) -> str | None:
        """Why a client may not publish as it advertised; None: it may (publisher ready)."""
        what = f"refused to publish on {_short(advert.topic)}"
        if advert.encoding != ENCODING:
            return f"{what}: encoding {_short(advert.encoding)!r}; only {ENCODING!r} (ROS 2)"
        msgtype = ros_message_type(advert.schema_name)
        if msgtype is None:
            return f"{what}: {_short(advert.schema_name)!r} is not a ROS message type"
        topic = advert.topic if advert.topic.startswith("/") else f"/{advert.topic}"
        try:
            if len(topic) > TOPIC_NAME_MAX:
                raise InvalidTopicNameException(topic, "too long", 0)
            validate_full_topic_name(topic)
        except InvalidTopicNameException:
            return f"{what}: not a valid ROS topic name"
        if is_internal_topic(topic) or topic in QUIET_TOPICS:
            return f"{what}: that topic belongs to ROS itself"
        try:
            py_type = import_type(msgtype, "msg")
        except ConversionError as exc:
            return f"{what}: {exc}"
        for name, types in self._node.get_topic_names_and_types():
            if name == topic and msgtype not in types:
                return f"{what}: it carries {', '.join(types)}, not {msgtype}"
        existing = self._publishers.get(topic)
        if existing is not None and existing.msgtype != msgtype:
            return f"{what}: it is already published as {existing.msgtype}"
        if existing is None:
            if len(self._publishers) >= self.limits.max_publishers:
                return f"{what}: at most {self.limits.max_publishers} topics may be published"
            publisher = self._node.create_publisher(py_type, topic, PUBLISH_QOS)
            self._publishers[topic] = _Publisher(publisher, py_type, msgtype)
        advert.topic, advert.msgtype = topic, msgtype
        return None

    def _let_go(self, advert: _Advert) -> None:
        entry = self._publishers.get(advert.topic)
        if entry is None:
            return
        entry.users.discard(advert.key)
        if not entry.users:
            self._drop_publisher(advert.topic)

    def _drop_publisher(self, topic: str) -> None:
        entry = self._publishers.pop(topic)
        self._node.destroy_publisher(entry.publisher)

    def _publish_inbox(self) -> None:
        with self._lock:
            items = list(self._inbox)
            self._inbox.clear()
            adverts = {key: self._adverts.get(key) for key, _data in items}
        later: list[tuple[ClientKey, bytes]] = []
        for key, data in items:
            advert = adverts[key]
            if advert is None:
                continue  # refused or unadvertised meanwhile (said then)
            if not advert.accepted:
                later.append((key, data))  # advertised just now: decided next round
                continue
            entry = self._publishers.get(advert.topic)
            if entry is None:
                continue
            try:
                message = deserialize_message(data, entry.py_type)
            except Exception:  # rclpy raises its RMWError for any malformed CDR
                self._note(
                    f"refused a message on {_short(advert.topic)}: not a valid CDR {advert.msgtype}"
                )
                continue
            # Published as we parsed it: whatever trailed the message does not reach ROS.
            entry.publisher.publish(message)
            self._published += 1
        if later:
            with self._lock:
                self._inbox.extendleft(reversed(later))
            self._wake.set()

    # ------------------------------------------------------------------ services

    def _read_services(self) -> None:
        if self._server is None:
            return
        now = time.monotonic()
        live: dict[str, str] = {}
        for name, types in self._node.get_service_names_and_types():
            if is_internal_topic(name) or ACTION_MARKER in name:
                continue
            if any(t.startswith(QUIET_SERVICE_PACKAGES) for t in types):
                continue
            if self._node.count_services(name) == 0:
                continue  # only clients (ours among them) name it: nobody answers
            if len(types) != 1:
                self._unusable_note(name, "+".join(types), "it is offered with several types")
                continue
            live[name] = types[0]
        for service in list(self._services.values()):
            srvtype = live.get(service.name)
            if srvtype == service.srvtype:
                service.gone_since = None
            elif srvtype is not None:
                self._close_service(service)  # now of another type: added again below
            elif service.gone_since is None:
                service.gone_since = now  # a server restarting is not a service gone
            elif now - service.gone_since >= self.limits.gone_after_sec:
                self._close_service(service)
        added: list[Service] = []
        for name, srvtype in sorted(live.items()):
            if name in self._services or (name, srvtype) in self._unusable:
                continue
            if len(self._services) >= self.limits.max_services:
                self._note(
                    f"offering only {self.limits.max_services} of {len(live)} services",
                    refusal=False,
                )
                break
            try:
                py_type = import_type(srvtype, "srv")
                request_text, response_text = service_definitions(srvtype)
            except (ConversionError, BagError) as exc:
                self._unusable_note(name, srvtype, str(exc))
                continue
            self._services[name] = _Service(name, srvtype, py_type)
            added.append(
                Service(
                    name,
                    schema=ServiceSchema(
                        srvtype,
                        request=_message_schema(f"{srvtype}_Request", request_text),
                        response=_message_schema(f"{srvtype}_Response", response_text),
                    ),
                    handler=self._on_call,
                )
            )
        if added:
            self._server.add_services(added)

    def _close_service(self, service: _Service, *, advertised: bool = True) -> None:
        del self._services[service.name]
        if advertised and self._server is not None:
            self._server.remove_services([service.name])
        for call in [c for c in self._sent if c.service == service.name]:
            self._end_call(call, f"{service.name} left the graph")
        if service.client is not None:
            self._node.destroy_client(service.client)
            service.client = None

    def _send_calls(self) -> None:
        """Send the new calls, and let go of those answered, abandoned or too late."""
        with self._lock:
            new, self._new_calls = self._new_calls, []
            over = {id(c) for c in self._sent if c.over}
        now = time.monotonic()
        for call in self._sent[:]:
            if id(call) in over or call.done.is_set():
                self._end_call(call, "")
            elif now >= call.deadline:
                self._end_call(call, f"{call.service} did not answer in time")
        for call in new:
            if call.done.is_set():
                continue  # failed meanwhile (the bridge is closing)
            service = self._services.get(call.service)
            if service is None:
                self._finish(call, error=f"{call.service} is not on the graph")
                continue
            try:
                request = deserialize_message(call.payload, service.py_type.Request)
            except Exception:  # rclpy raises its RMWError for any malformed CDR
                self._note(f"refused a call to {_short(call.service)}: not a valid CDR request")
                self._finish(call, error=f"not a valid CDR {service.srvtype} request")
                continue
            if service.client is None:
                service.client = self._node.create_client(service.py_type, service.name)
            call.request = request  # sent once its server is discovered
            self._sent.append(call)
        for call in self._sent:
            service = self._services.get(call.service)
            if call.future is None and service is not None and service.client is not None:
                if service.client.service_is_ready():
                    call.future = service.client.call_async(call.request)
                    call.future.add_done_callback(lambda f, c=call: self._answer(c, f))

    def _end_call(self, call: _Call, error: str) -> None:
        """The bridge's thread: forget a sent call (and its pending ROS request)."""
        self._sent.remove(call)
        future = call.future
        if future is not None and not future.done():
            service = self._services.get(call.service)
            if service is not None and service.client is not None:
                service.client.remove_pending_request(future)
            future.cancel()
        if error:
            self._finish(call, error=error)

    def _answer(self, call: _Call, future: Future) -> None:
        """The executor's thread: the ROS service answered (or the call was cancelled)."""
        if future.cancelled():
            return
        try:
            self._finish(call, response=serialize_message(future.result()))
        except Exception as exc:
            self._finish(call, error=f"{call.service} failed: {exc}")

    def _finish(self, call: _Call, *, response: bytes | None = None, error: str = "") -> None:
        """Hand the answer to the waiting handler (the first answer counts)."""
        with self._lock:
            if call.done.is_set():
                return
            call.response, call.error = response, error
            if response is not None:
                self._answered += 1
            call.done.set()
        self._wake.set()  # the bridge's thread lets go of it

    # ---------------------------------------------------------------- parameters

    def _settle_parameters(self) -> None:
        """Keep the cache fresh, one read per node at a time, and apply the queued sets."""
        limits = self.limits
        now = time.monotonic()
        with self._lock:
            asked, self._params_asked = self._params_asked, False
            sets = list(self._param_sets)
            self._param_sets.clear()
        # Nothing is read until a client shows it wants parameters: a learner who only
        # watches topics costs no parameter clients on every node.
        self._params_wanted = self._params_wanted or asked or bool(sets)
        if not self._params_wanted:
            return
        if now >= self._nodes_read_at + limits.refresh_sec:
            self._nodes_read_at = now
            live = {
                node_fqn(name, namespace)
                for name, namespace in self._node.get_node_names_and_namespaces()
            }
            for fqn in list(self._param_nodes):
                if fqn not in live:
                    self._forget_param_node(fqn)
            for fqn in sorted(live):
                if fqn in self._param_nodes or is_hidden_node(fqn):
                    continue
                if len(self._param_nodes) >= limits.max_parameter_nodes:
                    break
                self._param_nodes[fqn] = _ParamNode(
                    fqn,
                    self._node.create_client(ListParameters, f"{fqn}/list_parameters"),
                    self._node.create_client(GetParameters, f"{fqn}/get_parameters"),
                )
        for entry in self._param_nodes.values():
            try:
                self._read_parameters(entry, now, asked)
            except Exception:  # one odd node must not stop the others' reads
                log.exception("foxglove bridge: reading the parameters of %s", entry.fqn)
                entry.stage, entry.future, entry.read_at = "", None, now
        by_node: dict[str, list[RosParameter]] = {}
        for name, value in sets:
            fqn, dot, param = name.partition(".")
            known = self._param_cache.get(name)
            if not dot or fqn not in self._param_nodes:
                self._note(f"cannot set {_short(name)}: no such node (names are /node.param)")
                continue
            try:
                ros_value = parameter_value(_as_ros(value, known[0] if known else None))
            except Exception as exc:
                self._note(f"cannot set {_short(name)}: {exc}")
                continue
            by_node.setdefault(fqn, []).append(RosParameter(name=param, value=ros_value))
        for fqn, params in by_node.items():
            target = self._param_nodes[fqn]
            if target.set_client is None:
                target.set_client = self._node.create_client(SetParameters, f"{fqn}/set_parameters")
            target.setting.append(_ParamSet(SetParameters.Request(parameters=params), now))
        for entry in self._param_nodes.values():
            try:
                self._apply_sets(entry, now)
            except Exception as exc:  # said, and the sets dropped: never retried forever
                self._note(f"could not set parameters on {entry.fqn}: {exc}")
                entry.setting = []

    def _read_parameters(self, entry: _ParamNode, now: float, asked: bool) -> None:
        limits = self.limits
        if entry.stage and now - entry.started > limits.call_timeout_sec:
            client = entry.list_client if entry.stage == "list" else entry.get_client
            client.remove_pending_request(entry.future)
            entry.stage, entry.future = "", None
            entry.read_at = now  # not answering: tried again after the refresh period
        if entry.stage == "list" and entry.future.done():
            result = entry.future.result()
            entry.names = list(result.result.names)[: limits.max_parameters_per_node]
            entry.future = entry.get_client.call_async(GetParameters.Request(names=entry.names))
            entry.stage, entry.started = "get", now
        elif entry.stage == "get" and entry.future.done():
            values = entry.future.result().values
            fresh = {
                f"{entry.fqn}.{name}": (value.type, python_value(value))
                for name, value in zip(entry.names, values, strict=False)
                if value.type != 0  # PARAMETER_NOT_SET
            }
            self._store_parameters(entry.fqn, fresh)
            entry.stage, entry.future, entry.read_at = "", None, now
        age = float("inf") if entry.read_at is None else now - entry.read_at
        due = age >= limits.parameter_refresh_sec or (asked and age >= ASKED_REREAD_SEC)
        if not entry.stage and due and entry.list_client.service_is_ready():
            entry.future = entry.list_client.call_async(ListParameters.Request())
            entry.stage, entry.started = "list", now

    def _apply_sets(self, entry: _ParamNode, now: float) -> None:
        still: list[_ParamSet] = []
        for pending in entry.setting:
            names = ", ".join(p.name for p in pending.request.parameters)
            if now - pending.started > self.limits.call_timeout_sec:
                self._note(f"could not set {_short(names)} on {entry.fqn}: it did not answer")
                if pending.future is not None and entry.set_client is not None:
                    entry.set_client.remove_pending_request(pending.future)
                continue
            if pending.future is None:
                if entry.set_client is not None and entry.set_client.service_is_ready():
                    pending.future = entry.set_client.call_async(pending.request)
                still.append(pending)  # sent, or its server not discovered yet
                continue
            if not pending.future.done():
                still.append(pending)
                continue
            changed: dict[str, tuple[int, object]] = {}
            results = pending.future.result().results
            for param, result in zip(pending.request.parameters, results, strict=False):
                name = f"{entry.fqn}.{param.name}"
                if result.successful:
                    changed[name] = (param.value.type, python_value(param.value))
                else:
                    self._note(f"could not set {_short(name)}: {result.reason or 'refused'}")
            if changed:
                self._store_parameters(entry.fqn, changed, replace=False)
                if self._server is not None:
                    self._server.publish_parameter_values(
                        [_foxglove_parameter(n, *v) for n, v in changed.items()]
                    )
        entry.setting = still

    def _store_parameters(
        self, fqn: str, values: dict[str, tuple[int, object]], *, replace: bool = True
    ) -> None:
        prefix = f"{fqn}."
        with self._lock:
            cache = dict(self._param_cache)
            if replace:
                cache = {k: v for k, v in cache.items() if not k.startswith(prefix)}
            cache.update(values)
            self._param_cache = cache  # whole, for the listener's readers

    def _forget_param_node(self, fqn: str) -> None:
        entry = self._param_nodes.pop(fqn)
        for client in (entry.list_client, entry.get_client, entry.set_client):
            if client is not None:
                self._node.destroy_client(client)
        self._store_parameters(fqn, {})

    def _say_notes(self) -> None:
        with self._lock:
            notes = list(self._notes)
            self._notes.clear()
            self._recent.extend(notes)
        for text in notes:
            log.warning("foxglove: %s", text)
            if self._server is not None:
                self._server.publish_status(text, StatusLevel.Warning)


class _Listener(ServerListener):
    """The server's callbacks, handed to the bridge (which only records them)."""

    def __init__(self, bridge: FoxgloveBridge) -> None:
        self._bridge = bridge

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        self._bridge._on_watch(client.id, channel.id, True)

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        self._bridge._on_watch(client.id, channel.id, False)

    def on_client_advertise(self, client: Client, channel: ClientChannel) -> None:
        self._bridge._on_advertise(client.id, channel)

    def on_client_unadvertise(self, client: Client, client_channel_id: int) -> None:
        self._bridge._on_unadvertise(client.id, client_channel_id)

    def on_message_data(self, client: Client, client_channel_id: int, data: bytes) -> None:
        self._bridge._on_message(client.id, client_channel_id, data)

    def on_get_parameters(
        self, client: Client, param_names: list[str], request_id: str | None = None
    ) -> list[Parameter]:
        return self._bridge._on_get_parameters(param_names)

    def on_set_parameters(
        self, client: Client, parameters: list[Parameter], request_id: str | None = None
    ) -> list[Parameter]:
        return self._bridge._on_set_parameters(parameters)


def _foxglove_parameter(name: str, ros_type: int, value: Any) -> Parameter:
    """A cached ROS value as Foxglove's: doubles and byte arrays keep their type."""
    if ros_type == RosParameterType.PARAMETER_DOUBLE:
        return Parameter(name, value=float(value), type=ParameterType.Float64)
    if ros_type == RosParameterType.PARAMETER_DOUBLE_ARRAY:
        return Parameter(name, value=[float(v) for v in value], type=ParameterType.Float64Array)
    if ros_type == RosParameterType.PARAMETER_BYTE_ARRAY:
        return Parameter(name, value=bytes(value), type=ParameterType.ByteArray)
    return Parameter(name, value=value)


def _as_ros(value: object, ros_type: int | None) -> object:
    """A client's value, made the parameter's ROS type where JSON lost it (2.0 sent as 2)."""
    if ros_type == RosParameterType.PARAMETER_DOUBLE and isinstance(value, int):
        return float(value)
    if ros_type == RosParameterType.PARAMETER_DOUBLE_ARRAY and isinstance(value, list):
        return [float(v) for v in value]
    if isinstance(value, bytes | dict) or value is None:
        raise ValueError("only booleans, numbers, strings and lists of them are set here")
    return value


def _message_schema(name: str, text: str) -> MessageSchema:
    schema = foxglove.Schema(name=name, encoding=SCHEMA_ENCODING, data=text.encode())
    return MessageSchema(encoding=ENCODING, schema=schema)


def no_delay(port: int) -> int:
    """Nagle's algorithm off on this process's TCP connections served from ``port``.

    foxglove-sdk 0.30 leaves it on for its clients' sockets (ros-foxglove-bridge
    turns it off): a small message (an /odom) then waits for the client's
    delayed ACK whenever the one before is unacknowledged. Measured here: the
    p95 of /odom to a client 22 ms with it, 2.2 ms without (bench/foxglove_latency.py).
    The sockets are the library's; the option is all we touch. Returns how many.
    """
    try:
        connections = psutil.Process().net_connections(kind="tcp")
    except (psutil.Error, OSError):
        return 0
    done = 0
    for conn in connections:
        if conn.fd < 0 or conn.status != psutil.CONN_ESTABLISHED or conn.laddr.port != port:
            continue
        try:
            sock = socket.socket(fileno=conn.fd)  # the same descriptor, not a copy
        except OSError:
            continue  # closed meanwhile
        try:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            done += 1
        except OSError:
            pass
        finally:
            sock.detach()  # never close what the server owns
    return done


def _short(text: str, limit: int = 80) -> str:
    """A client's text as we repeat it: bounded (it may be megabytes of garbage)."""
    return text if len(text) <= limit else f"{text[:limit]}…"
