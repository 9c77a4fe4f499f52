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
 *          firstMergeWithParameters, initialClusters, name, levels?, skeleton?}
 * positions Float32Array (V*3, relative to header.center), triangles Uint32Array (T*3),
 * faceOfTriangle Uint32Array (T) or null for the identity, children Uint32Array ((F-1)*2),
 * rms Float64Array (F-1, merge nodes' RMS estimates, input units), types Uint8Array (F-1),
 * parameters Float64Array (9 per merge from firstMergeWithParameters to the last real one:
 * point 3 (relative to center), axis 3, radius, minor_radius, half_angle), leafRms or null.
 */
export async function readPageData(document) {
  const headerElement = document.getElementById('primseg-header');
  if (!headerElement) throw new Error('the page has no primseg data: was it written by primseg view?');
  const header = JSON.parse(headerElement.textContent);
  if (header.format !== 1) throw new Error(`unknown page data format ${header.format}`);
  const [positions, triangles, faceOfTriangle, children, rms, types, parameters, leafRms] =
    await Promise.all([
      readArray(document, 'positions', Float32Array),
      readArray(document, 'triangles', Uint32Array),
      readArray(document, 'face-of-triangle', Uint32Array, false),
      readArray(document, 'children', Uint32Array),
      readArray(document, 'rms', Float64Array),
      readArray(document, 'types', Uint8Array),
      readArray(document, 'parameters', Float64Array),
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
  return { header, positions, triangles, faceOfTriangle, children, rms, types, parameters, leafRms };
}
