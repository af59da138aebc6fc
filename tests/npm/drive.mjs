// A third-party client, @foxglove/ws-protocol (from the npm registry), driving otonav's
// live view as the Foxglove app does: it sets a parameter, then publishes a goal on
// /goal from a client channel (JSON). Every event is printed as one JSON line; the test
// (tests/smoke/test_foxglove_npm_client.py) reads them and judges the robot in sim time.
// Usage: node drive.mjs WS_URL GOAL_X GOAL_Y MAX_V   (ends when stdin closes)
import wsProtocol from "@foxglove/ws-protocol";
import { WebSocket } from "ws";

const { FoxgloveClient } = wsProtocol;

const [url, gx, gy, maxV] = [process.argv[2], ...process.argv.slice(3).map(Number)];
const out = (event) => process.stdout.write(JSON.stringify(event) + "\n");
const client = new FoxgloveClient({
  ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});

client.on("serverInfo", (info) => {
  out({ event: "serverInfo", capabilities: info.capabilities });
  client.setParameters([{ name: "nav.params.max_v", value: maxV }], "set");
});
client.on("parameterValues", (values) => {
  out({ event: "parameterValues", id: values.id, parameters: values.parameters });
  if (values.id !== "set") return;
  const channel = client.advertise({
    topic: "/goal",
    encoding: "json",
    schemaName: "geometry_msgs/msg/PoseStamped",
  });
  const goal = {
    header: { stamp: { sec: 0, nanosec: 0 }, frame_id: "odom" },
    pose: {
      position: { x: gx, y: gy, z: 0.0 },
      orientation: { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
    },
  };
  client.sendMessage(channel, new TextEncoder().encode(JSON.stringify(goal)));
  out({ event: "goalSent" });
});
client.on("status", (status) => out({ event: "status", ...status }));
client.on("error", (error) => out({ event: "error", message: String(error) }));
process.stdin.on("end", () => {
  client.close();
  process.exit(0);
});
process.stdin.resume();
