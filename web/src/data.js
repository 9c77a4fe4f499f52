// Reads the data that `primseg view` puts in the page (apps/view_command.cpp): a JSON header and
// little-endian typed arrays in base64, each in its own <script> element.

/** Decodes base64 (atob, then bytes: faster than a fetch of a data: URL in Chromium). */
function decodeBase64(text) {
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes.buffer;
}

async function readArray(document, name, ArrayType, required = true) {
  const element = document.getElementById('primseg-' + name);
  if (!element) {
    if (required) throw new Error(`the page has no '${name}' data: was it written by primseg view?`);
    return null;
  }
  const buffer = decodeBase64(element.textContent.trim());
  if (buffer.byteLength % ArrayType.BYTES_PER_ELEMENT !== 0)
    throw new Error(`'${name}' data: ${buffer.byteLength} bytes is not a whole number of values`);
  return new ArrayType(buffer);
}

/**
 * The page's data.
 * header: {faces F, vertices V, triangles T, components C, center [3], bboxDiagonal, weights,
 *          maxClustersWithParameters, initialClusters, name, levels?, skeleton?}
 * positions Float32Array (V*3, relative to header.center), triangles Uint32Array (T*3),
 * faceOfTriangle Uint32Array (T) or null for the identity, children Uint32Array ((F-1)*2),
 * rms Float64Array (F-1, merge nodes' RMS estimates, input units), types Uint8Array (F-1),
 * parameterNodes Uint32Array (ascending: every cluster of every level of at most
 * header.maxClustersWithParameters clusters, as primseg cut --clusters K makes them), and for
 * each of them the primitive primseg reports (the geometric fit, cut.hpp describe_clusters):
 * parameters Float64Array (9 per node: point 3 (relative to center), axis 3, radius,
 * minor_radius, half_angle) and errors Float64Array (2 per node: exact RMS and maximum distance
 * of the node's vertices to it, input units); leafRms or null.
 *
 * header.autoLevel: the automatic level's K (auto_level.hpp choose_level); header.levels: its
 * candidates [{clusters, rms, score, mergeScore}], best score first.
 *
 * header.skeleton (primseg view --skeleton): {clusters K, joints J, rootBone, band}, and then
 * `skeleton` holds (input units, absolute, not relative to center): rest Float64Array (V*3, the
 * mesh's positions as primseg read them), jointPositions Float64Array (J*3), jointKinds
 * Uint8Array (J: 0 sensitive, 1 locked, 2 virtual), jointVisible, boneVisible Uint8Array,
 * jointBoneOffsets/jointBones and boneJointOffsets/boneJoints (compressed rows, Uint32Array),
 * bonePoints Float64Array (K*3), boneOrder/boneParentJoint/boneParentBone Uint32Array (K, the
 * bone tree of skinning.hpp, 0xffffffff for none), weightOffsets Uint32Array (V+1), weightBones
 * Uint32Array, weightValues Float64Array (skin weights), faceLabels Uint32Array (F).
 *
 * header.relations (primseg view --regularize): {firstClusters K0, levels L, relations R, fits M,
 * kinds [names by kind code]}: the relations `primseg cut --clusters K --regularize` finds, for
 * each level K = K0 .. K0 + L - 1, and the fits they make exact. Then `relations` holds
 * levelOffsets Uint32Array (L+1: level K's relations are [levelOffsets[K - K0],
 * levelOffsets[K - K0 + 1])), kinds Uint8Array (R), memberOffsets Uint32Array (R+1) and members
 * Uint32Array (tree nodes: a relation's clusters, then for an orthogonal one the clusters of the
 * other direction), firstSide Uint32Array (R: how many members are its clusters), deviations
 * Float64Array (R: ClusterRelation::deviation, degrees or input units), fitOffsets
 * Uint32Array (L+1: level K's fits, as levelOffsets), fitNodes Uint32Array (M: the nodes the
 * relations refitted, increasing within a level), fitParameters Float64Array (9 per fit, as
 * parameters) and fitErrors Float64Array (2 per fit, as errors).
 */
export async function readPageData(document) {
  const headerElement = document.getElementById('primseg-header');
  if (!headerElement) throw new Error('the page has no primseg data: was it written by primseg view?');
  const header = JSON.parse(headerElement.textContent);
  if (header.format !== 2) throw new Error(`unknown page data format ${header.format}`);
  const [positions, triangles, faceOfTriangle, children, rms, types, parameterNodes, parameters, errors,
    leafRms] = await Promise.all([
      readArray(document, 'positions', Float32Array),
      readArray(document, 'triangles', Uint32Array),
      readArray(document, 'face-of-triangle', Uint32Array, false),
      readArray(document, 'children', Uint32Array),
      readArray(document, 'rms', Float64Array),
      readArray(document, 'types', Uint8Array),
      readArray(document, 'parameter-nodes', Uint32Array),
      readArray(document, 'parameters', Float64Array),
      readArray(document, 'errors', Float64Array),
      readArray(document, 'leaf-rms', Float64Array, false),
    ]);
  const F = header.faces;
  const check = (ok, what) => {
    if (!ok) throw new Error(`inconsistent page data: ${what}`);
  };
  check(positions.length === header.vertices * 3, 'positions');
  check(triangles.length === header.triangles * 3, 'triangles');
  check(faceOfTriangle ? faceOfTriangle.length === header.triangles : header.triangles === F,
    'faces of triangles');
  check(children.length === 2 * (F - 1) && rms.length === F - 1 && types.length === F - 1,
    'merges');
  check(parameters.length === 9 * parameterNodes.length && errors.length === 2 * parameterNodes.length &&
    parameterNodes.every((node, i) => node < 2 * F - 1 && (i === 0 || node > parameterNodes[i - 1])),
  'primitive parameters');
  const skeleton = header.skeleton ? await readSkeleton(document, header, check) : null;
  const relations = header.relations ? await readRelations(document, header, check) : null;
  return { header, positions, triangles, faceOfTriangle, children, rms, types, parameterNodes, parameters, errors,
    leafRms, skeleton, relations };
}

const RELATION_ARRAYS = {
  levelOffsets: Uint32Array, kinds: Uint8Array, memberOffsets: Uint32Array, members: Uint32Array,
  firstSide: Uint32Array, deviations: Float64Array, fitOffsets: Uint32Array, fitNodes: Uint32Array,
  fitParameters: Float64Array, fitErrors: Float64Array,
};

/** Reads the named arrays 'PREFIX-kebab-case-key' of `types` ({key: ArrayType}). */
async function readArrays(document, prefix, types) {
  const arrays = {};
  for (const [key, ArrayType] of Object.entries(types)) {
    const name = prefix + '-' + key.replace(/[A-Z]/g, (c) => '-' + c.toLowerCase());
    arrays[key] = await readArray(document, name, ArrayType);
  }
  return arrays;
}

async function readRelations(document, header, check) {
  const r = await readArrays(document, 'relations', RELATION_ARRAYS);
  const { levels: L, relations: R, fits: M } = header.relations, nodes = 2 * header.faces - 1;
  const offsets = (array, length, total) => array.length === length + 1 && array[0] === 0 &&
    array[length] === total && array.every((x, i) => i === 0 || x >= array[i - 1]);
  check(offsets(r.levelOffsets, L, R) && offsets(r.fitOffsets, L, M), 'relation levels');
  check(r.kinds.length === R && r.kinds.every((k) => k < header.relations.kinds.length) &&
    r.firstSide.length === R && offsets(r.memberOffsets, R, r.members.length) &&
    r.deviations.length === R && r.deviations.every((d) => d >= 0 && Number.isFinite(d)) &&
    r.members.every((node) => node < nodes), 'relations');
  check(r.fitNodes.length === M && r.fitParameters.length === 9 * M && r.fitErrors.length === 2 * M &&
    r.fitNodes.every((node) => node < nodes), 'relation fits');
  return r;
}

const SKELETON_ARRAYS = {
  rest: Float64Array, jointPositions: Float64Array, jointKinds: Uint8Array, jointVisible: Uint8Array,
  jointBoneOffsets: Uint32Array, jointBones: Uint32Array, boneJointOffsets: Uint32Array,
  boneJoints: Uint32Array, bonePoints: Float64Array, boneVisible: Uint8Array, boneOrder: Uint32Array,
  boneParentJoint: Uint32Array, boneParentBone: Uint32Array, weightOffsets: Uint32Array,
  weightBones: Uint32Array, weightValues: Float64Array, faceLabels: Uint32Array,
};

async function readSkeleton(document, header, check) {
  const skeleton = await readArrays(document, 'skeleton', SKELETON_ARRAYS);
  const J = header.skeleton.joints, K = header.skeleton.clusters, V = header.vertices;
  const s = skeleton;
  check(s.rest.length === 3 * V && s.weightOffsets.length === V + 1, 'skeleton rest positions');
  check(s.jointPositions.length === 3 * J && s.jointKinds.length === J && s.jointVisible.length === J &&
    s.jointBoneOffsets.length === J + 1, 'skeleton joints');
  check(s.bonePoints.length === 3 * K && s.boneVisible.length === K && s.boneJointOffsets.length === K + 1 &&
    s.boneOrder.length === K && s.boneParentJoint.length === K && s.boneParentBone.length === K, 'skeleton bones');
  check(s.weightBones.length === s.weightValues.length && s.weightOffsets[V] === s.weightBones.length,
    'skin weights');
  check(s.faceLabels.length === header.faces, 'skeleton face labels');
  return skeleton;
}
