// Poses and linear blend skinning in the page, the arithmetic of primseg's src/skinning.cpp step
// for step (same formulas, same order of operations), so that a pose gives the positions
// `primseg deform` gives, to round-off. Pure functions on the page's skeleton data (data.js).

export const JOINT_KINDS = ['sensitive', 'locked', 'virtual'];
export const SENSITIVE = 0, LOCKED = 1, VIRTUAL = 2;
const NONE = 0xffffffff;

/** A rigid transform x -> R x + t: R row-major Float64Array(9), t Float64Array(3). */
export function identity() {
  return { R: Float64Array.of(1, 0, 0, 0, 1, 0, 0, 0, 1), t: new Float64Array(3) };
}

/** Rotation by `angle` radians about the line through `centre` with direction `axis`. */
export function rotationAbout(centre, axis, angle) {
  const length = Math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  const inverse = 1.0 / length;
  const u = [inverse * axis[0], inverse * axis[1], inverse * axis[2]];
  const c = Math.cos(angle), s = Math.sin(angle), t = 1 - c;
  // Rodrigues' formula.
  const R = Float64Array.of(
    t * u[0] * u[0] + c, t * u[0] * u[1] - s * u[2], t * u[0] * u[2] + s * u[1],
    t * u[0] * u[1] + s * u[2], t * u[1] * u[1] + c, t * u[1] * u[2] - s * u[0],
    t * u[0] * u[2] - s * u[1], t * u[1] * u[2] + s * u[0], t * u[2] * u[2] + c);
  // Fixes the centre: x -> R (x - centre) + centre.
  const translation = new Float64Array(3);
  for (let i = 0; i < 3; ++i) {
    let rotated = 0;
    for (let j = 0; j < 3; ++j) rotated += R[3 * i + j] * centre[j];
    translation[i] = centre[i] - rotated;
  }
  return { R, t: translation };
}

/** transform(x), written into out[o..o+2]. */
export function applyTo(transform, x, out, o = 0) {
  const { R, t } = transform;
  for (let i = 0; i < 3; ++i) {
    let y = t[i];
    for (let j = 0; j < 3; ++j) y += R[3 * i + j] * x[j];
    out[o + i] = y;
  }
  return out;
}

/** a ∘ b: b first. */
export function compose(a, b) {
  const R = new Float64Array(9);
  for (let i = 0; i < 3; ++i)
    for (let j = 0; j < 3; ++j) {
      let sum = 0;
      for (let m = 0; m < 3; ++m) sum += a.R[3 * i + m] * b.R[3 * m + j];
      R[3 * i + j] = sum;
    }
  return { R, t: applyTo(a, b.t, new Float64Array(3)) };
}

function sameTransform(a, b) {
  for (let i = 0; i < 9; ++i) if (a.R[i] !== b.R[i]) return false;
  return a.t[0] === b.t[0] && a.t[1] === b.t[1] && a.t[2] === b.t[2];
}

/**
 * A skeleton of the page (data.skeleton, header.skeleton), posable as primseg deform poses.
 */
export class PosableSkeleton {
  constructor(skeleton, header) {
    this.s = skeleton;
    this.jointCount = header.skeleton.joints;
    this.boneCount = header.skeleton.clusters;
    this.vertexCount = header.vertices;
    // Rank of each bone in the pose's visiting order (the nearest-root bone carries a joint).
    this.rank = new Uint32Array(this.boneCount);
    skeleton.boneOrder.forEach((bone, i) => (this.rank[bone] = i));
  }

  jointPosition(joint) {
    const p = this.s.jointPositions;
    return [p[3 * joint], p[3 * joint + 1], p[3 * joint + 2]];
  }
  jointBones(joint) {
    return this.s.jointBones.subarray(this.s.jointBoneOffsets[joint], this.s.jointBoneOffsets[joint + 1]);
  }
  boneJoints(bone) {
    return this.s.boneJoints.subarray(this.s.boneJointOffsets[bone], this.s.boneJointOffsets[bone + 1]);
  }
  kind(joint) {
    return this.s.jointKinds[joint];
  }
  parentBone(bone) {
    const p = this.s.boneParentBone[bone];
    return p === NONE ? -1 : p;
  }
  parentJoint(bone) {
    const j = this.s.boneParentJoint[bone];
    return j === NONE ? -1 : j;
  }

  /** The bone hanging from a sensitive joint in the bone tree; throws as primseg does. */
  childOfJoint(joint) {
    if (!Number.isInteger(joint) || joint < 0 || joint >= this.jointCount)
      throw new Error(`joint ${joint} does not exist (${this.jointCount} joints)`);
    if (this.kind(joint) !== SENSITIVE)
      throw new Error(`joint ${joint} is ${JOINT_KINDS[this.kind(joint)]}: only sensitive joints rotate`);
    for (const bone of this.jointBones(joint)) if (this.s.boneParentJoint[bone] === joint) return bone;
    throw new Error(`joint ${joint} closes a cycle of the skeleton: it cannot rotate`);
  }

  /** Whether a joint can be turned by a drag, and which: the joint itself if sensitive, else
   *  for a virtual joint (a free end) the sensitive joint its bone hangs from; -1 for neither. */
  rotatedByDrag(joint) {
    if (this.kind(joint) === SENSITIVE) {
      try {
        this.childOfJoint(joint);
        return joint;
      } catch {
        return -1;
      }
    }
    if (this.kind(joint) !== VIRTUAL) return -1;
    const bone = this.jointBones(joint)[0];
    const parent = this.parentJoint(bone);
    return parent >= 0 && this.kind(parent) === SENSITIVE ? parent : -1;
  }

  /**
   * The rigid motion of every bone for a pose: rotations [{joint, axis [3], angle (radians)}],
   * as pose_bones. Throws for what primseg deform refuses.
   */
  poseBones(rotations) {
    const K = this.boneCount;
    const local = Array.from({ length: K }, identity);
    const posed = new Set();
    for (const { joint, axis, angle } of rotations) {
      const child = this.childOfJoint(joint);
      if (posed.has(joint)) throw new Error(`joint ${joint} is rotated twice`);
      posed.add(joint);
      const length = Math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
      if (!(Number.isFinite(length) && length > 0) || !Number.isFinite(angle))
        throw new Error(`joint ${joint}: the axis must be finite and non-zero, the angle finite`);
      local[child] = rotationAbout(this.jointPosition(joint), axis, angle);
    }
    const world = new Array(K);
    for (const bone of this.s.boneOrder) {
      const parent = this.parentBone(bone);
      world[bone] = parent < 0 ? local[bone] : compose(world[parent], local[bone]);
    }
    return world;
  }

  /** Linear blend skinning of the rest positions, as skin_positions, into `out` (V*3). */
  skin(transforms, out = new Float64Array(3 * this.vertexCount)) {
    const { rest, weightOffsets, weightBones, weightValues } = this.s;
    const x = [0, 0, 0], y = [0, 0, 0];
    for (let v = 0; v < this.vertexCount; ++v) {
      const begin = weightOffsets[v], end = weightOffsets[v + 1];
      x[0] = rest[3 * v];
      x[1] = rest[3 * v + 1];
      x[2] = rest[3 * v + 2];
      if (begin === end) {
        out.set(x, 3 * v);
        continue;
      }
      // A vertex whose bones all move alike moves exactly rigidly (no rounding from the blend).
      const first = transforms[weightBones[begin]];
      let rigid = true;
      for (let i = begin + 1; i < end && rigid; ++i) rigid = sameTransform(transforms[weightBones[i]], first);
      if (rigid) {
        applyTo(first, x, out, 3 * v);
        continue;
      }
      let s0 = 0, s1 = 0, s2 = 0;
      for (let i = begin; i < end; ++i) {
        const w = weightValues[i];
        applyTo(transforms[weightBones[i]], x, y);
        s0 = s0 + w * y[0];
        s1 = s1 + w * y[1];
        s2 = s2 + w * y[2];
      }
      out[3 * v] = s0;
      out[3 * v + 1] = s1;
      out[3 * v + 2] = s2;
    }
    return out;
  }

  /** Joint positions in a pose (J*3): a joint moves with its bone nearest the root. */
  posedJoints(transforms, out = new Float64Array(3 * this.jointCount)) {
    for (let joint = 0; joint < this.jointCount; ++joint) {
      const bones = this.jointBones(joint);
      let carrier = bones[0];
      for (const bone of bones) if (this.rank[bone] < this.rank[carrier]) carrier = bone;
      applyTo(transforms[carrier], this.jointPosition(joint), out, 3 * joint);
    }
    return out;
  }
}

/** The axis and angle of a rotation matrix (row-major), angle in [0, π]. */
export function axisAngle(R) {
  const trace = R[0] + R[4] + R[8];
  const angle = Math.acos(Math.max(-1, Math.min(1, (trace - 1) / 2)));
  let axis = [R[7] - R[5], R[2] - R[6], R[3] - R[1]];
  let length = Math.hypot(...axis);
  if (angle > Math.PI / 2 && length < 1e-6) {
    // Near a half turn the antisymmetric part vanishes: take the axis from R + I's largest column.
    const columns = [0, 1, 2].map((j) => [R[j] + (j === 0), R[3 + j] + (j === 1), R[6 + j] + (j === 2)]);
    axis = columns.reduce((a, b) => (Math.hypot(...b) > Math.hypot(...a) ? b : a));
    length = Math.hypot(...axis);
  }
  if (!(length > 0)) return { axis: [0, 0, 1], angle: 0 };
  return { axis: axis.map((x) => x / length), angle };
}
