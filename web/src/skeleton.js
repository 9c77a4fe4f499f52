// The skeleton overlay (pages written by `primseg view --skeleton`): bones drawn as sticks and
// joints as spheres over the mesh (sensitive joints green, virtual ones blue, locked ones as small
// grey cubes; hidden bones and joints are not drawn). Dragging a sensitive joint turns the part
// beyond it about the joint; dragging a virtual joint (a free end) turns its bone about the joint
// it hangs from. The rotation axis is the viewing direction and the angle follows the pointer
// around the joint on the screen. The mesh is posed live by linear blend skinning
// (skinning.js, the arithmetic of `primseg deform`).

import * as THREE from 'three';
import { registerOverlay } from './hooks.js';
import { PosableSkeleton, SENSITIVE, LOCKED, VIRTUAL, JOINT_KINDS, axisAngle, rotationAbout } from './skinning.js';

const JOINT_COLORS = { [SENSITIVE]: 0x5ce08a, [LOCKED]: 0x8d8f96, [VIRTUAL]: 0x6bb8ff };
const BONE_COLOR = 0xffe08a;
// Pixels around a joint that grab it.
const GRAB_PIXELS = 10;

/** Reads a pose: {rotations: [...]} as in primseg deform's POSE.json, or the list itself; each
 *  rotation {joint, axis [3], degrees} or {joint, axis, angle} (radians). */
function readRotations(pose) {
  const list = Array.isArray(pose) ? pose : pose?.rotations;
  if (!Array.isArray(list)) throw new Error('a pose is {"rotations": [{"joint", "axis", "degrees"}]}');
  return list.map((r) => ({
    joint: r.joint,
    axis: Array.from(r.axis ?? []),
    // As primseg's pose reader: degrees * pi / 180.
    angle: r.degrees !== undefined ? (r.degrees * Math.PI) / 180 : r.angle,
  }));
}

class SkeletonOverlay {
  constructor(context) {
    this.name = 'skeleton';
    this.context = context;
    this.header = context.header;
    this.center = context.header.center;
    this.skeleton = new PosableSkeleton(context.data.skeleton, context.header);
    this.triangles = context.data.triangles;
    this.rotations = new Map(); // joint -> {axis, angle} (rest coordinates of the part before it)
    this.deformed = new Float64Array(this.skeleton.s.rest);
    this.transforms = this.skeleton.poseBones([]);
    this.jointsNow = this.skeleton.posedJoints(this.transforms);
    this.buildScene();
    this.listen();
    this.setUpPanel();
    this.place();
  }

  buildScene() {
    const diagonal = this.header.bboxDiagonal || 1;
    const s = this.skeleton;
    this.group = new THREE.Group();
    this.group.renderOrder = 10;
    // Drawn through the mesh: the skeleton is inside it.
    const material = (color) => new THREE.MeshBasicMaterial({ color, depthTest: false, depthWrite: false, transparent: true, opacity: 0.95 });
    const sphere = new THREE.SphereGeometry(0.012 * diagonal, 16, 12);
    const cube = new THREE.BoxGeometry(0.014 * diagonal, 0.014 * diagonal, 0.014 * diagonal);
    this.jointMeshes = [];
    for (let joint = 0; joint < s.jointCount; ++joint) {
      if (!s.s.jointVisible[joint]) continue;
      const kind = s.kind(joint);
      const mesh = new THREE.Mesh(kind === LOCKED ? cube : sphere, material(JOINT_COLORS[kind]));
      mesh.renderOrder = 12;
      mesh.userData.joint = joint;
      this.jointMeshes.push(mesh);
      this.group.add(mesh);
    }
    // Sticks: a bone with two joints joins them; a hub bone joins its centre to each joint.
    this.sticks = [];
    const stick = new THREE.CylinderGeometry(0.004 * diagonal, 0.004 * diagonal, 1, 8, 1);
    const boneMaterial = material(BONE_COLOR);
    for (let bone = 0; bone < s.boneCount; ++bone) {
      if (!s.s.boneVisible[bone]) continue;
      const joints = Array.from(s.boneJoints(bone));
      const ends = joints.length === 2 ? [[{ joint: joints[0] }, { joint: joints[1] }]]
        : joints.map((joint) => [{ bone }, { joint }]);
      for (const [a, b] of ends) {
        const mesh = new THREE.Mesh(stick, boneMaterial);
        mesh.renderOrder = 11;
        this.sticks.push({ mesh, a, b, bone });
        this.group.add(mesh);
      }
    }
    this.context.scene.add(this.group);
  }

  // A stick end's position now, scene coordinates.
  endPoint(end) {
    const c = this.center;
    if (end.joint !== undefined) {
      const p = this.jointsNow;
      return new THREE.Vector3(p[3 * end.joint] - c[0], p[3 * end.joint + 1] - c[1], p[3 * end.joint + 2] - c[2]);
    }
    const q = this.skeleton.s.bonePoints, b = end.bone, y = [0, 0, 0];
    const t = this.transforms[b];
    for (let i = 0; i < 3; ++i) y[i] = t.t[i] + t.R[3 * i] * q[3 * b] + t.R[3 * i + 1] * q[3 * b + 1] + t.R[3 * i + 2] * q[3 * b + 2];
    return new THREE.Vector3(y[0] - c[0], y[1] - c[1], y[2] - c[2]);
  }

  // Places the drawn joints and sticks at the current pose.
  place() {
    const c = this.center, p = this.jointsNow;
    for (const mesh of this.jointMeshes) {
      const j = mesh.userData.joint;
      mesh.position.set(p[3 * j] - c[0], p[3 * j + 1] - c[1], p[3 * j + 2] - c[2]);
    }
    const up = new THREE.Vector3(0, 1, 0);
    for (const { mesh, a, b } of this.sticks) {
      const from = this.endPoint(a), to = this.endPoint(b);
      const direction = to.clone().sub(from);
      const length = direction.length();
      mesh.visible = length > 0;
      if (!mesh.visible) continue;
      mesh.position.copy(from).addScaledVector(direction, 0.5);
      mesh.quaternion.setFromUnitVectors(up, direction.divideScalar(length));
      mesh.scale.set(1, length, 1);
    }
  }

  /** The current pose, as primseg deform's POSE.json reads it (angles in degrees). */
  pose() {
    return {
      rotations: [...this.rotations].sort((a, b) => a[0] - b[0]).map(([joint, r]) => ({
        joint, axis: r.axis, degrees: (r.angle * 180) / Math.PI,
      })),
    };
  }

  /** Poses the mesh: every joint not in `pose` goes back to rest. Throws (and changes nothing)
   *  for a pose primseg deform refuses. */
  setPose(pose) {
    const rotations = readRotations(pose);
    const transforms = this.skeleton.poseBones(rotations);
    this.rotations = new Map(rotations.map((r) => [r.joint, { axis: r.axis, angle: r.angle }]));
    this.apply(transforms);
    this.context.geometry.computeBoundingSphere();
    this.context.requestRender();
  }

  resetPose() {
    this.setPose([]);
  }

  // Skins the mesh for bone transforms and updates what is drawn.
  apply(transforms) {
    this.transforms = transforms;
    this.skeleton.skin(transforms, this.deformed);
    this.jointsNow = this.skeleton.posedJoints(transforms, this.jointsNow);
    const attribute = this.context.geometry.getAttribute('position');
    const corners = attribute.array, triangles = this.triangles, d = this.deformed;
    const drawOrder = this.context.drawOrder, [cx, cy, cz] = this.center;
    for (let slot = 0; slot < drawOrder.length; ++slot)
      for (let k = 0; k < 3; ++k) {
        const v = 3 * triangles[3 * drawOrder[slot] + k], i = 9 * slot + 3 * k;
        corners[i] = d[v] - cx;
        corners[i + 1] = d[v + 1] - cy;
        corners[i + 2] = d[v + 2] - cz;
      }
    attribute.needsUpdate = true;
    this.place();
  }

  /** Posed vertex positions (input units, absolute), V*3 doubles. */
  positions() {
    return this.deformed;
  }

  /** Posed joint positions (input units, absolute), J*3 doubles. */
  jointPositions() {
    return this.jointsNow;
  }

  // ----- dragging -----

  /** Window (client) coordinates of a point of the scene. */
  toClient(point) {
    const rect = this.context.canvas.getBoundingClientRect();
    const ndc = point.clone().project(this.context.camera);
    return [rect.left + ((ndc.x + 1) / 2) * rect.width, rect.top + ((1 - ndc.y) / 2) * rect.height];
  }

  /** Client coordinates of a joint as drawn now (for tests and tools). */
  jointOnScreen(joint) {
    return this.toClient(this.endPoint({ joint }));
  }

  /** The drawn joint nearest a window point, within grabbing distance, or -1. */
  jointAt(x, y) {
    if (!this.group.visible) return -1;
    let best = -1, bestDistance = GRAB_PIXELS;
    for (const mesh of this.jointMeshes) {
      const [jx, jy] = this.toClient(mesh.position);
      const distance = Math.hypot(jx - x, jy - y);
      if (distance <= bestDistance) {
        best = mesh.userData.joint;
        bestDistance = distance;
      }
    }
    return best;
  }

  listen() {
    const canvas = this.context.canvas;
    // Capture phase on the canvas's parent: a grabbed joint keeps the pointer from the orbit
    // controls and from cluster picking, which listen on the canvas itself.
    canvas.parentElement.addEventListener('pointerdown', (event) => {
      if (event.target !== canvas || event.button !== 0) return;
      const joint = this.jointAt(event.clientX, event.clientY);
      if (joint < 0) return;
      const turned = this.skeleton.rotatedByDrag(joint);
      if (turned < 0) {
        this.say(`joint ${joint} is ${JOINT_KINDS[this.skeleton.kind(joint)]}: it does not move`);
        return; // the pointer goes on to the orbit controls
      }
      event.stopPropagation();
      event.preventDefault();
      this.startDrag(joint, turned, event);
    }, true);
    window.addEventListener('pointermove', (event) => {
      if (this.drag) this.moveDrag(event);
    });
    window.addEventListener('pointerup', () => {
      if (!this.drag) return;
      this.drag = null;
      this.context.geometry.computeBoundingSphere();
      this.say(`pose: ${this.rotations.size} joint${this.rotations.size === 1 ? '' : 's'} turned`);
    });
  }

  startDrag(grabbed, joint, event) {
    const s = this.skeleton;
    const child = s.childOfJoint(joint);
    // The handle: the grabbed free end, or for a grabbed sensitive joint the far side of the bone
    // beyond it (its other joints, else its centre).
    let handle;
    if (grabbed !== joint) handle = this.endPoint({ joint: grabbed });
    else {
      const others = Array.from(s.boneJoints(child)).filter((j) => j !== joint);
      handle = new THREE.Vector3();
      if (others.length) {
        for (const j of others) handle.add(this.endPoint({ joint: j }));
        handle.divideScalar(others.length);
      } else handle = this.endPoint({ bone: child });
    }
    // The viewing direction, towards the viewer, in the rest coordinates of the part before the
    // joint (a pose's axes are; rotations nearer the root carry them along).
    const camera = this.context.camera;
    const toViewer = camera.getWorldDirection(new THREE.Vector3()).negate();
    const parent = s.parentBone(child);
    const R = parent >= 0 ? this.transforms[parent].R : Float64Array.of(1, 0, 0, 0, 1, 0, 0, 0, 1);
    const w = [toViewer.x, toViewer.y, toViewer.z];
    const axis = [0, 1, 2].map((j) => R[j] * w[0] + R[3 + j] * w[1] + R[6 + j] * w[2]); // Rᵀ w
    const before = this.rotations.get(joint);
    this.drag = {
      joint, axis,
      pivot: this.toClient(this.endPoint({ joint })),
      handle: this.toClient(handle),
      start: [event.clientX, event.clientY],
      before: before ? rotationAbout([0, 0, 0], before.axis, before.angle).R : Float64Array.of(1, 0, 0, 0, 1, 0, 0, 0, 1),
    };
    this.say(`turning joint ${joint}`);
  }

  moveDrag(event) {
    const { joint, axis, pivot, handle, start, before } = this.drag;
    // Angle swept on the screen about the pivot by the handle moved with the pointer;
    // counter-clockwise on the screen (y up) is positive about the axis towards the viewer.
    const ax = handle[0] - pivot[0], ay = pivot[1] - handle[1];
    const bx = ax + event.clientX - start[0], by = ay - (event.clientY - start[1]);
    const angle = Math.atan2(ax * by - ay * bx, ax * bx + ay * by);
    const delta = rotationAbout([0, 0, 0], axis, angle).R;
    const M = new Float64Array(9);
    for (let i = 0; i < 3; ++i)
      for (let j = 0; j < 3; ++j)
        for (let m = 0; m < 3; ++m) M[3 * i + j] += delta[3 * i + m] * before[3 * m + j];
    const turned = axisAngle(M);
    if (turned.angle === 0) this.rotations.delete(joint);
    else this.rotations.set(joint, turned);
    this.apply(this.skeleton.poseBones([...this.rotations].map(([j, r]) => ({ joint: j, ...r }))));
    this.context.requestRender();
  }

  setUpPanel() {
    const row = document.getElementById('skeleton-row');
    if (!row) return;
    row.style.display = '';
    const show = document.getElementById('show-skeleton');
    show.addEventListener('change', () => {
      this.group.visible = show.checked;
      this.context.requestRender();
    });
    document.getElementById('reset-pose').addEventListener('click', () => {
      this.resetPose();
      this.say('rest pose');
    });
    document.getElementById('save-pose').addEventListener('click', () => this.savePose());
    const kinds = [0, 0, 0];
    for (let j = 0; j < this.skeleton.jointCount; ++j) ++kinds[this.skeleton.kind(j)];
    document.getElementById('skeleton-summary').textContent =
      `${this.skeleton.boneCount} bones, joints: ${kinds[SENSITIVE]} sensitive, ${kinds[VIRTUAL]} virtual, ${kinds[LOCKED]} locked`;
  }

  /** Downloads the current pose as pose.json: `primseg deform MESH SKEL.json pose.json -o OUT`
   *  then poses the mesh as the page shows it. */
  savePose() {
    const pose = this.pose();
    const url = URL.createObjectURL(new Blob([JSON.stringify(pose, null, 1) + '\n'], { type: 'application/json' }));
    const link = document.createElement('a');
    link.href = url;
    link.download = 'pose.json';
    link.click();
    // After the click has started the download (revoking at once may cancel it in some browsers).
    setTimeout(() => URL.revokeObjectURL(url), 0);
    const turned = pose.rotations.length;
    this.say(`pose.json saved: ${turned} joint${turned === 1 ? '' : 's'} turned`);
  }

  say(text) {
    this.message = text;
    const status = document.getElementById('status');
    if (status) status.textContent = text;
  }

  update() {
    // The skeleton is of one level; browsing other levels leaves it and the pose as they are.
  }

  dispose() {
    this.context.scene.remove(this.group);
  }
}

registerOverlay('skeleton', (context) => new SkeletonOverlay(context));
