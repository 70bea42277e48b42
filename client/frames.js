// Which frames wait for the decoder. Whole frames replace one another (only the newest is worth
// drawing), but a patch (stats.patch: a region of the image drawn over what came before it, sent
// while the view refines) must be drawn after everything before it, or its region would be lost.
// Pure: main.js decodes and draws.

/** Whether the frame (with its stats entry) is a patch. */
export function isPatch(frame) {
    return Boolean(frame?.entry?.stats?.patch);
}

/**
 * The queue after `frame` arrives while another decodes: {queue, dropped} where `dropped` lists the
 * frames it supersedes (to acknowledge unseen). A whole frame supersedes everything waiting; a patch
 * joins the end.
 */
export function enqueueFrame(queue, frame) {
    if (isPatch(frame)) return { queue: [...queue, frame], dropped: [] };
    return { queue: [frame], dropped: [...queue] };
}

/**
 * Where a patch goes: {width, height} of the whole image (the canvas is brought to it first, its
 * current picture stretched, as the server stretched its own) and the patch's {x, y}. Null for a
 * whole frame or a malformed patch.
 */
export function patchPlacement(stats, header) {
    const p = stats?.patch;
    const size = stats?.size;
    if (!p || !Array.isArray(size) || size.length !== 2) return null;
    const [width, height] = size;
    const ok = [p.x, p.y, width, height].every(Number.isInteger) && p.x >= 0 && p.y >= 0
        && p.x + header.width <= width && p.y + header.height <= height;
    return ok ? { width, height, x: p.x, y: p.y } : null;
}

/**
 * Whether a drawn frame's figures (the overlay's frame lines, the Stats details, the panels that
 * follow frames) are shown now, `lastShownAt` being when they last were (ms, as `now`). A refining
 * image's patches come many a second, and each shown would lay out and paint the page again, time the
 * page then does not spend on input: a patch's figures wait for `periodMs` after the last shown, except
 * the patch that completes the image. Whole frames always show theirs.
 */
export function figuresDue(stats, now, lastShownAt, periodMs) {
    if (!stats?.patch || stats.refine?.complete) return true;
    return now - lastShownAt >= periodMs;
}
