// The page's shared state and its change notices. main.js and the section modules read `store.state`;
// whoever changes something emits its topic, and every part that shows it subscribes, so no section
// calls another (client/README.md, "Modules"). Pure: node's test runner checks it.

export class Store {
    constructor(state = {}) {
        this.state = state;
        this.listeners = new Map(); // topic -> [fn]
    }

    /** Calls fn(...args) on every emit of `topic`, in subscription order; returns the unsubscribe. */
    on(topic, fn) {
        const list = this.listeners.get(topic) ?? [];
        list.push(fn);
        this.listeners.set(topic, list);
        return () => {
            const current = this.listeners.get(topic) ?? [];
            this.listeners.set(topic, current.filter((f) => f !== fn));
        };
    }

    /**
     * Tells the subscribers of `topic`. A subscriber that throws does not keep the others from hearing
     * it; the first error is rethrown after all were called.
     */
    emit(topic, ...args) {
        let failure = null;
        for (const fn of [...(this.listeners.get(topic) ?? [])]) {
            try {
                fn(...args);
            } catch (e) {
                failure ??= e;
            }
        }
        if (failure) throw failure;
    }

    /** Topics with at least one subscriber (for tests and the console). */
    topics() {
        return [...this.listeners].filter(([, list]) => list.length > 0).map(([topic]) => topic).sort();
    }
}
