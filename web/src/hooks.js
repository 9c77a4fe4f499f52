// Extension points for what other issues add to the page.
//
// - Automatic levels: `primseg view` writes `"levels": [{clusters, rms, score, mergeScore}, ...]` and
//   `"autoLevel": K` in the page header; they are marked on the error plot and offered as buttons
//   (main.js: showLevels).
// - Overlays: an overlay is an object {name, update(cut), dispose()} made by a factory registered
//   here with a header key; the viewer calls the factory when the page header has that key, with
//   the context below, and calls update() after every change of level. The skeleton
//   (skeleton.js, key "skeleton") is one: dragging joints is its own business (it gets the
//   camera, the canvas and the mesh geometry, whose positions it deforms, then calls
//   requestRender()).

const factories = new Map();

/**
 * Registers an overlay for pages whose header has `key`.
 * @param key header key, e.g. 'skeleton'
 * @param factory (context) => {update(cut), dispose()}; context: {header, value (header[key]),
 *   data, tree, scene, camera, canvas, geometry (non-indexed: triangle slot s has corners 3s..3s+2),
 *   drawOrder (the triangle of each slot), requestRender}
 */
export function registerOverlay(key, factory) {
  factories.set(key, factory);
}

/** The overlays a page's header asks for. */
export function createOverlays(context) {
  const overlays = [];
  for (const [key, factory] of factories)
    if (context.header[key] !== undefined) overlays.push(factory({ ...context, value: context.header[key] }));
  return overlays;
}
