// What the scene's file asks for and the renderer does not show (stats.not_shown, protocol/PROTOCOL.md),
// as the Scene section lists it. Pure, so node's test runner checks it.

/**
 * The lines for a frame's stats.not_shown: [{feature, text}], in the server's order; entries that are
 * not {feature, detail} strings are left out. An empty list: the file shows as it asks.
 */
export function notShownLines(notShown) {
    if (!Array.isArray(notShown)) return [];
    return notShown
        .filter((n) => n && typeof n.feature === 'string' && typeof n.detail === 'string')
        .map((n) => ({ feature: n.feature, text: `${n.feature}: ${n.detail}` }));
}

/** The section's one-line summary above the list. */
export function notShownSummary(lines) {
    if (!lines.length) return '';
    return lines.length === 1 ? 'The file uses 1 feature this renderer does not show:'
        : `The file uses ${lines.length} features this renderer does not show:`;
}
