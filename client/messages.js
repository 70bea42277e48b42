// What the page says about server errors (PROTOCOL.md, "error" codes): one clear sentence for the
// user, plus the server's own message and the field it points at.

const EXPLANATIONS = {
    invalid_json: 'The server could not read a message from this page.',
    invalid_message: 'The server refused a message from this page.',
    unknown_type: 'The server does not know a message this page sent.',
    invalid_param: 'The server refused a parameter value.',
    unknown_technique: 'The server does not offer that technique.',
    unknown_scene: 'The server does not offer that scene.',
    unknown_light: 'The session has no light with that id (it may have been removed): pick one in the Light section.',
    limit_exceeded: 'That is over the server\'s limits.',
    message_too_large: 'A message was over the server\'s size limit.',
    binary_not_accepted: 'The server accepts no binary messages.',
    rate_limited: 'Too many messages per second; the server dropped one.',
    read_only: 'This is a view-only link: the view cannot be steered from here.',
    render_failed: 'The renderer failed and ended this session (the server goes on): press Connect to start a new one.',
    scene_load_failed: 'The scene could not be loaded; the previous scene keeps rendering.',
    hello_required: 'The connection did not start properly.',
    protocol_mismatch: 'This page and the server speak different protocol versions: reload the page.',
    unauthorized: 'The server needs an access token: open the page with #token=YOUR_TOKEN in its address.',
    resume_failed: 'The previous session has expired (or the server restarted): starting a new one.',
    unknown_view_token: 'This view-only link is no longer valid: the session it showed has ended.',
    busy: 'The server is at its session limit: retrying.',
    idle_timeout: 'The session ended after a long time without input: press Connect to start a new one.',
    session_ended: 'The session has ended: press Connect to start a new one.',
};

/** The text to show for a server `error` message: explanation, then the server's details. */
export function describeError(msg) {
    const explanation = EXPLANATIONS[msg?.code] ?? `The server reported an error (${msg?.code ?? 'unknown'}).`;
    const details = [msg?.where ? `at ${msg.where}` : '', msg?.message ?? ''].filter(Boolean).join(': ');
    return details ? `${explanation} (${details})` : explanation;
}

/** The text for an HTTP API error body {error, message, where} with status `status`. */
export function describeHttpError(status, body) {
    const what = body?.message ?? body?.error ?? `HTTP ${status}`;
    const where = body?.where ? ` at ${body.where}` : '';
    if (status === 503) return `The server is busy rendering (${what}); try again shortly.`;
    if (status === 401) return 'The server needs an access token: open the page with #token=YOUR_TOKEN in its address.';
    if (status === 413) return `Too large for the server (${what}).`;
    return `The server refused the request${where}: ${what}`;
}

/**
 * The toasts over the view: at most `max`, each gone `ttlMs` after it was last shown. The same
 * text again (a burst of "busy" errors) counts up on the toast already there instead of stacking
 * copies over a small view.
 */
export class MessageStack {
    constructor({ max = 4, ttlMs = 8000 } = {}) {
        this.max = max;
        this.ttlMs = ttlMs;
        this.entries = []; // {id, text, kind, count, expires}, oldest first
        this.nextId = 1;
    }

    /** Adds or counts a message; returns {entry, added: bool, dropped: [entries pushed out]}. */
    add(text, kind, now) {
        const same = this.entries.find((e) => e.text === text && e.kind === kind);
        if (same) {
            same.count += 1;
            same.expires = now + this.ttlMs;
            // Newest last, so that the repeated one is not the next to be pushed out.
            this.entries.splice(this.entries.indexOf(same), 1);
            this.entries.push(same);
            return { entry: same, added: false, dropped: [] };
        }
        const entry = { id: this.nextId++, text, kind, count: 1, expires: now + this.ttlMs };
        this.entries.push(entry);
        const dropped = this.entries.length > this.max ? this.entries.splice(0, this.entries.length - this.max) : [];
        return { entry, added: true, dropped };
    }

    /** Removes and returns the entries expired at `now`. */
    expire(now) {
        const gone = this.entries.filter((e) => e.expires <= now);
        if (gone.length) this.entries = this.entries.filter((e) => e.expires > now);
        return gone;
    }

    clear() {
        this.entries = [];
    }
}

/**
 * The persistent notice for an error after which this page cannot go on by itself: {title, text,
 * action} where action is 'connect' (start a new session), 'own-session' (leave a dead view link
 * for a session of one's own), 'reload' or null. Null for errors the page recovers from.
 */
export function noticeFor(code, { viewer = false } = {}) {
    switch (code) {
    case 'unknown_view_token':
        return {
            title: 'This view link has expired',
            text: 'The session it showed has ended (or the server restarted). Ask whoever shared it for a new '
                + 'link, or start a session of your own.',
            action: 'own-session',
        };
    case 'session_ended':
        return viewer ? {
            title: 'The session you were watching has ended',
            text: 'Its controller disconnected, so this view link no longer works. Ask for a new link, or start a '
                + 'session of your own.',
            action: 'own-session',
        } : {
            title: 'This session has ended',
            text: 'Another tab or device took it over, or it was ended. Connect starts a new session.',
            action: 'connect',
        };
    case 'idle_timeout':
        return {
            title: 'The session ended after a long time without input',
            text: 'The server frees idle sessions. Connect starts a new one with the scene and settings you had.',
            action: 'connect',
        };
    case 'render_failed':
        return {
            title: 'The renderer failed',
            text: 'The server ended this session (it keeps serving others). Connect starts a new one.',
            action: 'connect',
        };
    case 'unauthorized':
        return {
            title: 'This server needs an access token',
            text: 'Open the page with #token=YOUR_TOKEN at the end of its address (ask whoever runs the server).',
            action: null,
        };
    case 'protocol_mismatch':
        return {
            title: 'This page is out of date',
            text: 'The page and the server speak different protocol versions: reload the page.',
            action: 'reload',
        };
    default:
        return null;
    }
}
