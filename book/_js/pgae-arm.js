// NICO's arm for the live playground's drawings: forward kinematics of the simulator's arm (not in
// the paper). window.pgaeArm.fk(arm, q): ``arm`` the manifest's arm (pgae_lite/web/assets.py: the
// shoulder's place and the links' lengths), ``q`` the 5 joint angles in radians; returns the
// shoulder, elbow, wrist and fingertip, each [x, y, z] in metres. pgae.js offers it as
// window.pgae.fk(q); tests/test_live_playground.py checks it against pybullet.
(function () {
  "use strict";

  // NICO's fingertip and arm at joint angles q (radians), by forward kinematics of the simulator's arm
  // (pgae_lite.sim.robot.nico_urdf: shoulder z, shoulder -y, arm x, elbow -y, wrist -y): the shoulder,
  // elbow, wrist and fingertip, each [x, y, z] in metres (NICO's frame, which is the world's).
  function fk(a, q) {
    const mul = (A, B) => A.map(r => [0, 1, 2].map(j => r[0] * B[0][j] + r[1] * B[1][j] + r[2] * B[2][j]));
    const rz = t => [[Math.cos(t), -Math.sin(t), 0], [Math.sin(t), Math.cos(t), 0], [0, 0, 1]];
    const ry = t => [[Math.cos(t), 0, Math.sin(t)], [0, 1, 0], [-Math.sin(t), 0, Math.cos(t)]];
    const rx = t => [[1, 0, 0], [0, Math.cos(t), -Math.sin(t)], [0, Math.sin(t), Math.cos(t)]];
    const down = (p, R, l) => p.map((v, i) => v - R[i][2] * l);           // p + R (0, 0, -l)
    const R1 = mul(mul(rz(q[0]), ry(-q[1])), rx(q[2]));                  // about +z, -y, +x
    const elbow = down(a.shoulder, R1, a.upper_arm);
    const R2 = mul(R1, ry(-q[3]));                                       // the elbow, about -y
    const wrist = down(elbow, R2, a.forearm);
    const tip = down(wrist, mul(R2, ry(-q[4])), a.fingertip);            // the wrist, about -y
    return [a.shoulder, elbow, wrist, tip];
  }

  window.pgaeArm = {fk};
})();
