#pragma once
// A small mobile whose pieces end up resting on each other: for the collision tests and the command
// line's contact report.

namespace aloft::test {

// Two 30 mm steel balls on 0.5 m threads from points 40 mm apart, drawn swung 10 degrees apart. Released,
// they swing together, knock (e = 0.3), and settle leaning on each other 1.15 degrees off the vertical,
// each pushed against the other by gravity. (They must hang from separate points of the hook: a
// component and its parent never collide.)
inline const char* const kLeaningBalls = R"({
  "name": "leaning balls", "contact": {"restitution": 0.3, "friction": 0.5},
  "damping": {"linear": 0.5, "angular": 0.5},
  "components": [
    {"name": "hook", "fixed": true, "shapes": [{"wire": {"from": [-0.03, 1, 0], "to": [0.03, 1, 0], "radius": 0.003}}]},
    {"name": "left", "parent": "hook", "joint": [-0.02, 1, 0], "shapes": [
      {"wire": {"from": [-0.02, 1, 0], "to": [-0.10682408883346517, 0.5075961234938124, 0], "radius": 0.0005}},
      {"sphere": {"center": [-0.10682408883346517, 0.5075961234938124, 0], "radius": 0.03}}]},
    {"name": "right", "parent": "hook", "joint": [0.02, 1, 0], "shapes": [
      {"wire": {"from": [0.02, 1, 0], "to": [0.10682408883346517, 0.5075961234938124, 0], "radius": 0.0005}},
      {"sphere": {"center": [0.10682408883346517, 0.5075961234938124, 0], "radius": 0.03}}]}]})";

}  // namespace aloft::test
