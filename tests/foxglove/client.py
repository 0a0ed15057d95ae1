"""A Foxglove WebSocket client for tests and the latency benchmark: the protocol, spoken plainly.

Written from the protocol's specification (foxglove/ws-protocol docs/spec.md),
with the ``websockets`` package, so that it can also send what a real client
never would. It offers both names of the protocol: ``foxglove.sdk.v1`` (the
only one foxglove-sdk 0.30's server accepts; Foxglove's app offers it) and
``foxglove.websocket.v1`` (the published spec's, the only one
``@foxglove/ws-protocol`` 0.8 offers).

Server to client: JSON ``serverInfo``, ``advertise``, ``unadvertise``,
``status``, ``advertiseServices``, ``unadvertiseServices``,
``serviceCallFailure``, ``parameterValues``; binary opcode 1 (message data): u32 subscription id,
u64 log time (ns), payload; binary opcode 3 (service call response): u32
service id, u32 call id, u32 encoding length, encoding, payload; all
little-endian. Client to server: JSON ``subscribe``, ``unsubscribe``,
``advertise``, ``unadvertise``; binary opcode 1 (client message data): u32
client channel id, payload; binary opcode 2 (service call request), laid out
as the response; JSON ``getParameters``, ``setParameters`` (each with an id the
``parameterValues`` answer repeats).
"""

from __future__ import annotations

import itertools
import json
import struct
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection
from websockets.typing import Subprotocol

from tests.wire_client import connect_quietly, frames_until_closed

SUBPROTOCOLS = [Subprotocol("foxglove.sdk.v1"), Subprotocol("foxglove.websocket.v1")]
MESSAGE_DATA = 0x01
SERVICE_CALL_REQUEST = 0x02  # client to server
SERVICE_CALL_RESPONSE = 0x03  # server to client
FETCH_ASSET_RESPONSE = 0x04  # server to client: request id, status (0 ok), error, data
KEEP = 2000  # messages kept per subscription (the count goes on)


@dataclass(frozen=True)
class CallResult:
    """How a service call ended: a response (payload) or a failure (message)."""

    service: int
    call: int
    encoding: str = ""
    payload: bytes | None = None
    failure: str | None = None


@dataclass(frozen=True)
class Received:
    subscription: int
    log_time: int  # ns, the server's receive time
    payload: bytes
    arrived: float  # time.time() when this client read it


class FoxgloveClient:
    """Connects, reads in a thread, and keeps what the server said."""

    def __init__(
        self,
        url: str,
        *,
        on_message: Callable[[Received], None] | None = None,
        timeout: float = 10.0,
        subprotocols: list[Subprotocol] | None = None,
    ) -> None:
        """``subprotocols``: what the client offers (Foxglove's app: both names)."""
        self.url = url
        self.ws: ClientConnection = connect_quietly(
            url, subprotocols=subprotocols or SUBPROTOCOLS, max_size=None, open_timeout=timeout
        )
        self.subprotocol = self.ws.subprotocol
        self._lock = threading.Lock()
        self._on_message = on_message
        self.server_info: dict[str, Any] | None = None
        self.assets: dict[int, tuple[int, str, bytes]] = {}  # request -> (status, error, data)
        self.channels: dict[int, dict[str, Any]] = {}
        self.statuses: list[dict[str, Any]] = []
        self.received: dict[int, deque[Received]] = {}
        self.services: dict[int, dict[str, Any]] = {}
        self.call_results: dict[int, CallResult] = {}  # by call id
        self.parameter_values: list[dict[str, Any]] = []  # parameterValues messages, in order
        self.counts: dict[int, int] = {}
        self._subscription_ids = itertools.count(1)
        self._channel_ids = itertools.count(1)
        self._call_ids = itertools.count(1)
        self.closed = threading.Event()
        self._closing = threading.Event()
        self._reader = threading.Thread(target=self._read, name="foxglove-client", daemon=True)
        self._reader.start()

    # ------------------------------------------------------------------ reading

    def _read(self) -> None:
        try:
            for frame in frames_until_closed(self.ws, self._closing):
                if isinstance(frame, str):
                    self._on_json(json.loads(frame))
                elif frame and frame[0] == MESSAGE_DATA and len(frame) >= 13:
                    sub, log_time = struct.unpack_from("<IQ", frame, 1)
                    got = Received(sub, log_time, bytes(frame[13:]), time.time())
                    with self._lock:
                        self.received.setdefault(sub, deque(maxlen=KEEP)).append(got)
                        self.counts[sub] = self.counts.get(sub, 0) + 1
                    if self._on_message is not None:
                        self._on_message(got)
                elif frame and frame[0] == FETCH_ASSET_RESPONSE and len(frame) >= 10:
                    request, status, length = struct.unpack_from("<IBI", frame, 1)
                    error = bytes(frame[10 : 10 + length]).decode()
                    with self._lock:
                        self.assets[request] = (status, error, bytes(frame[10 + length :]))
                elif frame and frame[0] == SERVICE_CALL_RESPONSE and len(frame) >= 13:
                    service, call, length = struct.unpack_from("<III", frame, 1)
                    encoding = bytes(frame[13 : 13 + length]).decode()
                    result = CallResult(service, call, encoding, bytes(frame[13 + length :]))
                    with self._lock:
                        self.call_results[call] = result
        except ConnectionClosed:
            pass
        finally:
            self.closed.set()

    def _on_json(self, message: dict[str, Any]) -> None:
        op = message.get("op")
        with self._lock:
            if op == "serverInfo":
                self.server_info = message
            elif op == "advertise":
                for channel in message["channels"]:
                    self.channels[channel["id"]] = channel
            elif op == "unadvertise":
                for channel_id in message["channelIds"]:
                    self.channels.pop(channel_id, None)
            elif op == "status":
                self.statuses.append(message)
            elif op == "advertiseServices":
                for service in message["services"]:
                    self.services[service["id"]] = service
            elif op == "unadvertiseServices":
                for service_id in message["serviceIds"]:
                    self.services.pop(service_id, None)
            elif op == "parameterValues":
                self.parameter_values.append(message)
            elif op == "serviceCallFailure":
                call = message["callId"]
                self.call_results[call] = CallResult(
                    message["serviceId"], call, failure=message.get("message", "")
                )

    # ------------------------------------------------------------------ queries

    def channel(self, topic: str) -> dict[str, Any] | None:
        with self._lock:
            return next((c for c in self.channels.values() if c["topic"] == topic), None)

    def topics(self) -> set[str]:
        with self._lock:
            return {c["topic"] for c in self.channels.values()}

    def messages(self, subscription: int) -> list[Received]:
        with self._lock:
            return list(self.received.get(subscription, ()))

    def count(self, subscription: int) -> int:
        with self._lock:
            return self.counts.get(subscription, 0)

    def service(self, name: str) -> dict[str, Any] | None:
        with self._lock:
            return next((s for s in self.services.values() if s["name"] == name), None)

    def call_result(self, call: int) -> CallResult | None:
        with self._lock:
            return self.call_results.get(call)

    def status_texts(self) -> list[str]:
        with self._lock:
            return [s.get("message", "") for s in self.statuses]

    def wait_for(self, predicate: Callable[[], Any], timeout: float, what: str) -> Any:
        deadline = time.monotonic() + timeout
        while True:
            value = predicate()
            if value:
                return value
            if time.monotonic() > deadline:
                raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
            time.sleep(0.02)

    # ------------------------------------------------------------------ sending

    def send_json(self, message: dict[str, Any]) -> None:
        self.ws.send(json.dumps(message))

    def subscribe(self, channel_id: int) -> int:
        sub = next(self._subscription_ids)
        self.send_json({"op": "subscribe", "subscriptions": [{"id": sub, "channelId": channel_id}]})
        return sub

    def subscribe_topic(self, topic: str, timeout: float = 30.0) -> int:
        channel = self.wait_for(lambda: self.channel(topic), timeout, f"a channel for {topic}")
        return self.subscribe(channel["id"])

    def unsubscribe(self, subscription: int) -> None:
        self.send_json({"op": "unsubscribe", "subscriptionIds": [subscription]})

    def advertise(self, topic: str, schema_name: str, encoding: str = "cdr") -> int:
        channel_id = next(self._channel_ids)
        self.send_json(
            {
                "op": "advertise",
                "channels": [
                    {
                        "id": channel_id,
                        "topic": topic,
                        "encoding": encoding,
                        "schemaName": schema_name,
                    }
                ],
            }
        )
        return channel_id

    def unadvertise(self, channel_id: int) -> None:
        self.send_json({"op": "unadvertise", "channelIds": [channel_id]})

    def publish(self, channel_id: int, payload: bytes) -> None:
        self.ws.send(struct.pack("<BI", MESSAGE_DATA, channel_id) + payload)

    def call_service(self, service_id: int, payload: bytes, encoding: str = "cdr") -> int:
        """Send a serviceCallRequest; the answer lands in ``call_results`` by the id returned."""
        call = next(self._call_ids)
        raw = encoding.encode()
        header = struct.pack("<BIII", SERVICE_CALL_REQUEST, service_id, call, len(raw))
        self.ws.send(header + raw + payload)
        return call

    def call(self, service_id: int, payload: bytes, timeout: float = 15.0) -> CallResult:
        """A service call, waited for."""
        call = self.call_service(service_id, payload)
        return self.wait_for(lambda: self.call_result(call), timeout, f"the answer to call {call}")

    def get_parameters(self, names: list[str], timeout: float = 10.0) -> dict[str, Any]:
        """getParameters, waited for: {name: value} (no names: every parameter known)."""
        request = f"get-{next(self._call_ids)}"
        self.send_json({"op": "getParameters", "parameterNames": names, "id": request})
        answer = self.wait_for(lambda: self._parameters_answer(request), timeout, request)
        return {p["name"]: p.get("value") for p in answer["parameters"]}

    def set_parameters(self, values: dict[str, Any]) -> str:
        """setParameters with an id (the server answers with parameterValues)."""
        request = f"set-{next(self._call_ids)}"
        parameters = [{"name": name, "value": value} for name, value in values.items()]
        self.send_json({"op": "setParameters", "parameters": parameters, "id": request})
        return request

    def _parameters_answer(self, request: str) -> dict[str, Any] | None:
        with self._lock:
            return next((m for m in self.parameter_values if m.get("id") == request), None)

    def fetch_asset(self, uri: str, timeout: float = 10.0) -> tuple[int, str, bytes]:
        """(status, error, data) of a fetchAsset: status 0 is found."""
        request = next(self._channel_ids)
        self.send_json({"op": "fetchAsset", "uri": uri, "requestId": request})
        return self.wait_for(lambda: self.assets.get(request), timeout, f"asset {uri}")

    def close(self) -> None:
        self._closing.set()
        self._reader.join(5.0)
