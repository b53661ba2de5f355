// The live view of the virtual Scorpion: draws the room and the robot
// from the server's WebSocket messages (docs/WORLD.md, "The live view")
// and sends the console's lines, the controls and the drags back.
"use strict";

const SVG = "http://www.w3.org/2000/svg";
const svg = document.getElementById("room");
const statusBox = document.getElementById("status");
const consoleBox = document.getElementById("console");
let socket = null;
let room = null;
let world = null;
let robot = null;
let trail = null;
let trailGroup = null;
// [x, y, jump]: a jump is a point the robot was put at by a drag, not
// driven to; the stretch into it is drawn dashed, not as trail.
let trailPoints = [];
// Where the stretch #trail draws begins in trailPoints.
let stretchStart = 0;
let pose = null;
let paused = false;
let dragging = null;

function el(name, attributes, parent) {
  const node = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes || {})) node.setAttribute(key, value);
  if (parent) parent.appendChild(node);
  return node;
}

function pointsText(points) {
  return points.map(([x, y]) => `${x},${y}`).join(" ");
}

// The trail: a polyline a driven stretch, a dashed line a jump; #trail
// is the stretch the robot drives now.
function drawTrail() {
  if (!trailGroup) return;
  trailGroup.textContent = "";
  const stretch = (points) =>
    el("polyline", { class: "trail", points: pointsText(points), fill: "none", stroke: "#06c", "stroke-width": 0.5 }, trailGroup);
  stretchStart = 0;
  trailPoints.forEach(([x, y, jump], index) => {
    if (!jump || index === 0) return;
    stretch(trailPoints.slice(stretchStart, index));
    const [fromX, fromY] = trailPoints[index - 1];
    el("line", { class: "jump", x1: fromX, y1: fromY, x2: x, y2: y, stroke: "#06c", "stroke-width": 0.5, "stroke-dasharray": "1.5 1.5" }, trailGroup);
    stretchStart = index;
  });
  trail = stretch(trailPoints.slice(stretchStart));
  trail.id = "trail";
}

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

function note(kind, text) {
  const line = document.createElement("div");
  line.className = kind;
  line.textContent = (kind === "sent" ? "> " : kind === "answer" ? "< " : "! ") + text;
  consoleBox.appendChild(line);
  while (consoleBox.childElementCount > 500) consoleBox.removeChild(consoleBox.firstChild);
  consoleBox.scrollTop = consoleBox.scrollHeight;
}

// Where a pointer event falls on the floor, in centimetres.
function floorPoint(event) {
  const point = svg.createSVGPoint();
  point.x = event.clientX;
  point.y = event.clientY;
  return point.matrixTransform(world.getScreenCTM().inverse());
}

function bounds(r) {
  let points = [];
  if (r.walls) points = points.concat(r.walls);
  for (const o of r.obstacles) {
    if (o.circle) {
      points.push([o.circle.x - o.circle.radius, o.circle.y - o.circle.radius]);
      points.push([o.circle.x + o.circle.radius, o.circle.y + o.circle.radius]);
    } else points = points.concat(o.polygon);
  }
  for (const line of r.lines) points = points.concat(line.points);
  points.push([r.start.x, r.start.y]);
  const margin = r.body.radius + 5;
  if (!r.walls) {
    // An open floor: room to drive around the start.
    points.push([r.start.x - 150, r.start.y - 100], [r.start.x + 150, r.start.y + 100]);
  }
  const xs = points.map((p) => p[0]);
  const ys = points.map((p) => p[1]);
  return {
    minX: Math.min(...xs) - margin, maxX: Math.max(...xs) + margin,
    minY: Math.min(...ys) - margin, maxY: Math.max(...ys) + margin,
  };
}

function drawRoom(r) {
  room = r;
  const keptTrail = trailPoints;
  svg.textContent = "";
  if (!r) {
    svg.setAttribute("viewBox", "0 0 100 20");
    el("text", { x: 2, y: 12, "font-size": 5 }, svg).textContent =
      "No room: give a world file (--world room.toml) to see the robot move.";
    return;
  }
  const b = bounds(r);
  // North up: the world's y runs up, the picture's down.
  svg.setAttribute("viewBox", `${b.minX} ${-b.maxY} ${b.maxX - b.minX} ${b.maxY - b.minY}`);
  world = el("g", { id: "world", transform: "scale(1 -1)" }, svg);
  if (r.walls) {
    el("polygon", { class: "walls", points: pointsText(r.walls), fill: "none", stroke: "black", "stroke-width": 2 }, world);
  }
  for (const line of r.lines) {
    el("polyline", { class: "line", points: pointsText(line.points), fill: "none", stroke: "#333", "stroke-width": line.width }, world);
  }
  r.obstacles.forEach((o, index) => {
    const shape = o.circle
      ? el("circle", { cx: o.circle.x, cy: o.circle.y, r: o.circle.radius }, world)
      : el("polygon", { points: pointsText(o.polygon) }, world);
    shape.setAttribute("class", "obstacle");
    shape.dataset.index = index;
    shape.addEventListener("pointerdown", (event) => startDrag(event, { obstacle: index, shape, o }));
  });
  trailGroup = el("g", { id: "trails" }, world);
  trailPoints = keptTrail;
  drawTrail();
  drawRobot(r.body);
}

function arc(radius, from, to) {
  const a = (from * Math.PI) / 180;
  const c = (to * Math.PI) / 180;
  const large = to - from > 180 ? 1 : 0;
  return `M ${radius * Math.cos(a)} ${radius * Math.sin(a)} A ${radius} ${radius} 0 ${large} 1 ${radius * Math.cos(c)} ${radius * Math.sin(c)}`;
}

function drawRobot(body) {
  robot = el("g", { id: "robot" }, world);
  el("circle", { r: body.radius, fill: "rgba(0,102,204,0.08)", stroke: "#06c", "stroke-width": 0.8 }, robot);
  el("line", { x1: 0, y1: 0, x2: body.radius, y2: 0, stroke: "#06c", "stroke-width": 0.8 }, robot);
  body.bumpers.forEach((middle, bit) => {
    // Drawn in the flipped frame: an arc counter-clockwise on the floor.
    const path = el("path", {
      class: "bumper", "data-bit": bit,
      d: arc(body.radius, middle - body.bumper_arc / 2, middle + body.bumper_arc / 2),
      fill: "none", stroke: "#bbb", "stroke-width": 1.6,
    }, robot);
    el("title", {}, path).textContent = `bumper ${bumperName(bit)}`;
  });
  for (const [name, [forward, left]] of [["right", body.right_tracker], ["left", body.left_tracker]]) {
    const dot = el("circle", { class: "tracker", "data-side": name, cx: forward, cy: left, r: 1, fill: "#444" }, robot);
    el("title", {}, dot).textContent = `${name} tracker`;
  }
  for (const [name, left] of [["left", 4], ["right", -4]]) {
    const dot = el("circle", { class: "eye", "data-side": name, cx: body.radius - 3, cy: left, r: 1.5, fill: "#555" }, robot);
    el("title", {}, dot).textContent = `${name} eye`;
  }
  robot.addEventListener("pointerdown", (event) => startDrag(event, { robot: true }));
  if (pose) placeRobot(pose);
}

function placeRobot(p) {
  if (!robot) return;
  robot.setAttribute("transform", `translate(${p.x} ${p.y}) rotate(${p.heading})`);
  robot.dataset.x = p.x;
  robot.dataset.y = p.y;
  robot.dataset.heading = p.heading;
}

// Where on the outline a bumper sits, in words: its angle from straight
// ahead (degrees, counter-clockwise) to the nearest eighth of a turn.
const SIDES = ["front", "front-left", "left", "back-left", "back", "back-right", "right", "front-right"];
function side(degrees) {
  return SIDES[((Math.round(degrees / 45) % 8) + 8) % 8];
}

// The bumpers' names: the bit and, with a room, where the bumper is.
function bumperName(bit) {
  const angle = room && room.body.bumpers[bit];
  return angle === undefined ? `${bit}` : `${bit} ${side(angle)}`;
}

// A list of labelled indicators: each a dot, its name, and its state
// in words (for screen readers and tests; the dot shows it). `items` are
// [key, name, on]; the list is rebuilt when the names change.
function switches(box, items, words) {
  const names = items.map(([key, name]) => `${key}:${name}`).join(",");
  if (box.dataset.names !== names) {
    box.textContent = "";
    for (const [key, name] of items) {
      const item = document.createElement("li");
      item.className = "switch";
      item.dataset.key = key;
      item.dataset.name = name;
      const dot = document.createElement("span");
      dot.className = box.id === "bumpers" ? "bit" : "lamp";
      dot.setAttribute("aria-hidden", "true");
      const label = document.createElement("span");
      label.className = "name";
      label.textContent = name;
      const state = document.createElement("span");
      state.className = "state";
      item.append(dot, label, " ", state);
      box.appendChild(item);
    }
    box.dataset.names = names;
  }
  items.forEach(([, , on], index) => {
    const item = box.children[index];
    item.classList.toggle("on", on);
    item.querySelector(".state").textContent = on ? words[0] : words[1];
  });
}

function showState(s) {
  paused = s.paused;
  document.getElementById("pause").textContent = paused ? "Run" : "Pause";
  document.getElementById("time").textContent = `${(s.ms / 1000).toFixed(3)} s${paused ? " (paused)" : ""} at ${s.speed}×`;
  const bumpers = [];
  for (let bit = 7; bit >= 0; bit--) bumpers.push([bit, bumperName(bit), ((s.bumpers >> bit) & 1) === 1]);
  switches(document.getElementById("bumpers"), bumpers, ["closed", "open"]);
  switches(document.getElementById("trackers"), [
    [1, "left", ((s.trackers >> 1) & 1) === 1],
    [0, "right", (s.trackers & 1) === 1],
  ], ["lit", "dark"]);
  switches(document.getElementById("lamps"), [["lamps", "tracker lamps", s.lamps]], ["on", "off"]);
  switches(document.getElementById("eyes"), [
    ["left", "left", s.eyes[0]],
    ["right", "right", s.eyes[1]],
  ], ["on", "off"]);
  document.getElementById("motors").textContent = `left ${s.motors[0]}, right ${s.motors[1]} steps`;
  for (const line of s.console) note(line.kind, line.text);
  if (s.trail.length && trail) {
    const jumps = new Set(s.jumps || []);
    s.trail.forEach(([x, y], index) => trailPoints.push([x, y, jumps.has(index)]));
    const trimmed = trailPoints.length > 50000;
    if (trimmed) trailPoints = trailPoints.slice(-40000);
    if (jumps.size || trimmed) drawTrail();
    else trail.setAttribute("points", pointsText(trailPoints.slice(stretchStart)));
  }
  if (s.pose) {
    pose = s.pose;
    document.getElementById("pose").textContent = `x=${s.pose.x.toFixed(1)} cm y=${s.pose.y.toFixed(1)} cm heading=${s.pose.heading.toFixed(1)}°`;
    if (!dragging || !dragging.robot) placeRobot(s.pose);
  }
  if (robot) {
    for (const path of robot.querySelectorAll(".bumper")) {
      path.setAttribute("stroke", (s.bumpers >> Number(path.dataset.bit)) & 1 ? "#c00" : "#bbb");
    }
    for (const dot of robot.querySelectorAll(".tracker")) {
      const lit = (s.trackers >> (dot.dataset.side === "left" ? 1 : 0)) & 1;
      dot.setAttribute("fill", lit ? "#fc0" : s.lamps ? "#864" : "#444");
    }
    for (const dot of robot.querySelectorAll(".eye")) {
      const on = s.eyes[dot.dataset.side === "left" ? 0 : 1];
      dot.setAttribute("fill", on ? "#fc0" : "#555");
    }
  }
}

function startDrag(event, what) {
  event.preventDefault();
  event.stopPropagation();
  const at = floorPoint(event);
  dragging = { ...what, from: at, turn: event.shiftKey, last: at };
  svg.setPointerCapture(event.pointerId);
}

svg.addEventListener("pointermove", (event) => {
  if (!dragging) return;
  const at = floorPoint(event);
  dragging.last = at;
  const dx = at.x - dragging.from.x;
  const dy = at.y - dragging.from.y;
  if (dragging.robot && pose) {
    if (dragging.turn) {
      const heading = (Math.atan2(at.y - pose.y, at.x - pose.x) * 180) / Math.PI;
      placeRobot({ x: pose.x, y: pose.y, heading });
    } else placeRobot({ x: pose.x + dx, y: pose.y + dy, heading: pose.heading });
  } else if (dragging.shape) {
    dragging.shape.setAttribute("transform", `translate(${dx} ${dy})`);
  }
});

svg.addEventListener("pointerup", () => {
  if (!dragging) return;
  const d = dragging;
  dragging = null;
  const dx = d.last.x - d.from.x;
  const dy = d.last.y - d.from.y;
  if (d.robot && pose) {
    const heading = d.turn ? Number(robot.dataset.heading) : pose.heading;
    send({ type: "move_robot", x: d.turn ? pose.x : pose.x + dx, y: d.turn ? pose.y : pose.y + dy, heading });
  } else if (d.shape) {
    const o = d.o;
    let middle;
    if (o.circle) middle = [o.circle.x, o.circle.y];
    else {
      const n = o.polygon.length;
      middle = [o.polygon.reduce((s, p) => s + p[0], 0) / n, o.polygon.reduce((s, p) => s + p[1], 0) / n];
    }
    send({ type: "move_obstacle", index: d.obstacle, x: middle[0] + dx, y: middle[1] + dy });
  }
});

document.getElementById("pause").addEventListener("click", () => send({ type: paused ? "run" : "pause" }));
document.getElementById("step").addEventListener("click", () => send({ type: "step", ms: 100 }));
document.getElementById("speed").addEventListener("change", (event) => send({ type: "speed", factor: Number(event.target.value) }));
document.getElementById("command-form").addEventListener("submit", (event) => {
  event.preventDefault();
  const input = document.getElementById("command");
  if (input.value) send({ type: "send", text: input.value });
  input.value = "";
});

function connect() {
  socket = new WebSocket(`ws://${location.host}/ws`);
  socket.addEventListener("open", () => {
    statusBox.textContent = "connected";
    statusBox.dataset.state = "open";
  });
  socket.addEventListener("close", (event) => {
    // The server says why when it closes (1009: a message too big).
    statusBox.textContent = event.reason
      ? `disconnected: ${event.reason} (reload to reconnect)`
      : "disconnected: is `scorpion sim --view` still running? (reload to reconnect)";
    statusBox.dataset.state = "closed";
    statusBox.dataset.code = event.code;
  });
  socket.addEventListener("message", (event) => {
    const message = JSON.parse(event.data);
    if (message.type === "room") drawRoom(message.room);
    else if (message.type === "state") showState(message);
    else if (message.type === "error") note("error", message.message);
  });
}

connect();
