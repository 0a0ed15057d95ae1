// What Lichtblick does on "Open connection": @foxglove/ws-protocol's FoxgloveClient over a
// WebSocket offering "foxglove.websocket.v1". Run by tests/foxglove/test_ws_protocol_client.py:
//   node client.js URL SUBSCRIBE_TOPIC PUBLISH_TOPIC PAYLOAD_HEX
// Prints one JSON line per event the test reads, and ends after the publish (or 30 s).
"use strict";
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");

const [url, subscribeTopic, publishTopic, payloadHex] = process.argv.slice(2);
const say = (event) => process.stdout.write(JSON.stringify(event) + "\n");
const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
let subscribed = false;
let received = 0;

client.on("serverInfo", (info) => {
  say({ event: "serverInfo", name: info.name, capabilities: info.capabilities, protocol: ws.protocol });
});
client.on("advertise", (channels) => {
  for (const channel of channels) {
    if (channel.topic === subscribeTopic && !subscribed) {
      subscribed = true;
      client.subscribe(channel.id);
      say({ event: "subscribed", topic: channel.topic, schemaName: channel.schemaName, encoding: channel.encoding });
    }
  }
});
client.on("message", (message) => {
  received += 1;
  if (received === 5) {
    say({ event: "messages", count: received, last: Buffer.from(message.data.buffer, message.data.byteOffset, message.data.byteLength).toString("hex") });
    const channel = client.advertise({ topic: publishTopic, encoding: "cdr", schemaName: "std_msgs/msg/String" });
    const payload = Uint8Array.from(Buffer.from(payloadHex, "hex"));
    let sent = 0;
    const timer = setInterval(() => {
      client.sendMessage(channel, payload);
      sent += 1;
      if (sent === 20) {
        clearInterval(timer);
        say({ event: "published", count: sent });
        client.close();
        process.exit(0);
      }
    }, 250);
  }
});
client.on("error", (error) => say({ event: "error", message: String(error && error.message) }));
client.on("close", () => say({ event: "close" }));
setTimeout(() => { say({ event: "timeout", received }); process.exit(2); }, 30000);
