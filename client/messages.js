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
