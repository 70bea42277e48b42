// The stream's WebSocket with automatic reconnect. A server that restarts or a laptop that wakes
// up should find its way back without a page reload, but without hammering a server that is down.

import { SUBPROTOCOL } from './protocol.js';

export const BACKOFF_START_MS = 500;
export const BACKOFF_MAX_MS = 8000;

/** Delay before reconnect attempt number `attempt` (0-based): 0.5 s doubling up to 8 s. */
export function backoffDelay(attempt) {
    return Math.min(BACKOFF_MAX_MS, BACKOFF_START_MS * 2 ** Math.max(0, attempt));
}

/** ws(s)://<same host>/ws for a page at `location`. */
export function streamUrl(location) {
    const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
    return `${scheme}//${location.host}/ws`;
}

/**
 * What the page URL asks for: {view, token}, each a string or undefined. `#view=TOKEN` joins a
 * session as a viewer; the server token may come as `#token=` (kept out of server logs and
 * Referer headers) or `?token=`.
 */
export function pageOptions(location) {
    const hash = new URLSearchParams(location.hash.replace(/^#/, ''));
    const query = new URLSearchParams(location.search);
    const pick = (value) => (value ? value : undefined);
    return { view: pick(hash.get('view')), token: pick(hash.get('token') ?? query.get('token')) };
}

/**
 * The view-only link for a session: this page with `#view=<view token>`. The query stays (a
 * `?token=` there is what a viewer of a server with a token needs too); a `#token=` does not, so
 * whoever shares a link decides whether the server token goes with it.
 */
export function shareLink(location, viewToken) {
    return `${location.origin}${location.pathname}${location.search}#view=${encodeURIComponent(viewToken)}`;
}

/**
 * Handlers: onOpen(), onText(string), onBinary(ArrayBuffer), onClose(code), onState(state, detail)
 * with state one of 'connecting', 'open', 'waiting' (detail: ms until the next attempt) and
 * 'closed'.
 */
export class StreamConnection {
    constructor(url, handlers) {
        this.url = url;
        this.handlers = handlers;
        this.socket = null;
        this.attempt = 0;
        this.retryTimer = null;
        this.stopped = false;
    }

    connect() {
        this.stopped = false;
        clearTimeout(this.retryTimer);
        this.handlers.onState?.('connecting');
        const socket = new WebSocket(this.url, SUBPROTOCOL);
        socket.binaryType = 'arraybuffer';
        this.socket = socket;
        // Every handler checks that its socket is still the current one: events of a socket that
        // was replaced must not touch the new session.
        socket.onopen = () => {
            if (socket !== this.socket) return;
            this.handlers.onState?.('open');
            this.handlers.onOpen?.();
        };
        socket.onmessage = (e) => {
            if (socket !== this.socket) return;
            if (typeof e.data === 'string') this.handlers.onText?.(e.data);
            else this.handlers.onBinary?.(e.data);
        };
        socket.onclose = (e) => {
            if (socket !== this.socket) return;
            this.socket = null;
            this.handlers.onClose?.(e.code);
            this.scheduleReconnect();
        };
        // onclose follows every error; the reconnect is scheduled there.
        socket.onerror = () => {};
    }

    /** The session is known good (welcome arrived): the next outage starts the backoff afresh. */
    markHealthy() {
        this.attempt = 0;
    }

    scheduleReconnect() {
        if (this.stopped) {
            this.handlers.onState?.('closed');
            return;
        }
        const delay = backoffDelay(this.attempt++);
        this.handlers.onState?.('waiting', delay);
        this.retryTimer = setTimeout(() => this.connect(), delay);
    }

    /**
     * The server refused the connection for good (a bad token, another protocol version): when it
     * closes the socket, stay closed instead of retrying.
     */
    stopReconnecting() {
        this.stopped = true;
        clearTimeout(this.retryTimer);
    }

    get isOpen() {
        return this.socket !== null && this.socket.readyState === WebSocket.OPEN;
    }

    /** Sends a message object as JSON; returns false when there is no open socket. */
    send(msg) {
        if (!this.isOpen) return false;
        this.socket.send(JSON.stringify(msg));
        return true;
    }

    /**
     * A close the user asked for: status 1000 tells the server to end the session at once
     * instead of keeping it for a resume (any other loss keeps it for the grace period).
     */
    close() {
        this.stopReconnecting();
        const socket = this.socket;
        this.socket = null;
        socket?.close(1000, 'user closed');
        this.handlers.onState?.('closed');
    }
}

/** The reconnect countdown: whole seconds from 1 s, tenths below ("retrying in 3 s", "0.4 s"). */
export function formatCountdown(ms) {
    const left = Math.max(0, ms);
    return left >= 1000 ? `${Math.ceil(left / 1000)} s` : `${(left / 1000).toFixed(1)} s`;
}
