// 2D canvases drawn over the 3D view (box selection, control net): sized to the view in device
// pixels and placed over it.

/**
 * Sizes and places `overlay` over `canvas` and clears it; returns its 2D context, its size in
 * device pixels and the device-pixel ratio.
 */
export function fitOverlay(overlay, canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (overlay.width !== w || overlay.height !== h) { overlay.width = w; overlay.height = h; }
  Object.assign(overlay.style, { left: `${canvas.offsetLeft}px`, top: `${canvas.offsetTop}px`, width: `${canvas.clientWidth}px`, height: `${canvas.clientHeight}px` });
  const g = overlay.getContext('2d');
  g.clearRect(0, 0, w, h);
  return { g, w, h, dpr };
}
