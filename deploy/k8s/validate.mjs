// Validates deploy/k8s against the Kubernetes API schemas, offline, and checks that the manifests
// agree with each other, with the server and with the image (docs/operations.md, "Kubernetes").
//
//   node deploy/k8s/validate.mjs [--self-test] [DIR]        (default DIR: deploy/k8s)
//
// Schemas: the npm package kubernetes-models (pinned in package.json), which ships the Kubernetes 1.33
// OpenAPI schemas compiled into validators, so nothing is downloaded at run time. Its validators
// accept unknown fields, as the API server's non-strict decoding does; this script is strict: it
// records which properties a validator reads (every property the schema declares is looked at) and
// reports every field of the manifest that no schema knows, e.g. a misspelt `readinessprobe`.
//
// Checked: every *.yaml document on its own; every kustomization.yaml built (resources, bases,
// namespace, images, JSON 6902 patches: the subset these manifests use) and its output validated
// again, so overlays' patched objects are checked too; then across each build: GI_* variables
// exist in the server's sources, probes use /healthz, the drain fits the termination grace period
// and liveness cannot kill a draining pod, selectors and references match, the HPA's custom metrics
// are served by the prometheus-adapter rules, runAsUser is the image's user, and the batch requests
// are valid POST /api/render bodies (protocol/http/render_request.json).
import { existsSync, readdirSync, readFileSync, statSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import Ajv2020 from 'ajv/dist/2020.js';
import { parse as parseYaml, parseAllDocuments } from 'yaml';

const REPO = fileURLToPath(new URL('../../', import.meta.url));
const args = process.argv.slice(2);
const selfTest = args.includes('--self-test');
const ROOT = path.resolve(args.find((a) => !a.startsWith('--')) ?? path.join(REPO, 'deploy/k8s'));

let failures = 0;
let passes = 0;
const fail = (where, what) => {
    ++failures;
    console.log(`FAIL ${where}: ${what}`);
};
const pass = (where, what) => {
    ++passes;
    console.log(`ok   ${where}: ${what}`);
};

// ---- schema validation ---------------------------------------------------------------------------

const modelCache = new Map();
async function modelFor(apiVersion, kind) {
    const key = `${apiVersion}/${kind}`;
    if (!modelCache.has(key)) {
        const [group, version] = apiVersion.includes('/') ? apiVersion.split('/') : [null, apiVersion];
        const module = `kubernetes-models/${group ? `${group}/` : ''}${version}/${kind}`;
        modelCache.set(key, await import(module).then((m) => m[kind]).catch(() => null));
    }
    return modelCache.get(key);
}

/** A deep copy whose objects record the property names read from them (by the validator). */
function tracked(value, pointer, seen) {
    if (value === null || typeof value !== 'object') return value;
    const read = new Set();
    const copy = Array.isArray(value)
        ? value.map((v, i) => tracked(v, `${pointer}/${i}`, seen))
        : Object.fromEntries(Object.entries(value).map(([k, v]) => [k, tracked(v, `${pointer}/${k.replaceAll('~', '~0').replaceAll('/', '~1')}`, seen)]));
    if (!Array.isArray(value)) seen.push({ pointer, value, read });
    return new Proxy(copy, {
        get(target, key, receiver) {
            if (typeof key === 'string') read.add(key);
            return Reflect.get(target, key, receiver);
        },
    });
}

/** Schema errors and unknown fields of one object; [] when valid. */
async function schemaProblems(doc) {
    if (!doc || typeof doc !== 'object' || !doc.apiVersion || !doc.kind) return ['not a Kubernetes object (apiVersion and kind)'];
    const Model = await modelFor(doc.apiVersion, doc.kind);
    if (!Model) return [`no schema for ${doc.apiVersion} ${doc.kind} in kubernetes-models`];
    const seen = [];
    const proxy = tracked(doc, '', seen);
    try {
        Model.prototype.validate.call(proxy);
    } catch (e) {
        return [String(e.message ?? e)];
    }
    const unknown = [];
    for (const { pointer, value, read } of seen)
        for (const key of Object.keys(value)) if (!read.has(key)) unknown.push(`${pointer}/${key}`);
    return unknown.map((p) => `unknown field ${p}`);
}

const describe = (doc) => `${doc?.kind ?? '?'} ${doc?.metadata?.namespace ? `${doc.metadata.namespace}/` : ''}${doc?.metadata?.name ?? '?'}`;

async function validateDocs(where, docs) {
    for (const doc of docs) {
        const problems = await schemaProblems(doc);
        if (problems.length) fail(`${where} ${describe(doc)}`, problems.join('; '));
        else pass(`${where} ${describe(doc)}`, `valid ${doc.apiVersion} ${doc.kind}`);
    }
}

// ---- files and kustomizations --------------------------------------------------------------------

function yamlFiles(dir) {
    const out = [];
    for (const name of readdirSync(dir).sort()) {
        const p = path.join(dir, name);
        if (statSync(p).isDirectory()) out.push(...yamlFiles(p));
        else if (/\.ya?ml$/.test(name)) out.push(p);
    }
    return out;
}

function readDocs(file) {
    const docs = [];
    for (const d of parseAllDocuments(readFileSync(file, 'utf8'))) {
        if (d.errors.length) throw new Error(`${file}: ${d.errors[0].message}`);
        const value = d.toJS();
        if (value !== null) docs.push(value);
    }
    return docs;
}

const unescapePointer = (s) => s.replaceAll('~1', '/').replaceAll('~0', '~');

/** RFC 6902 add, replace and remove (what the overlays use). */
function applyJsonPatch(doc, ops, where) {
    for (const op of ops) {
        const parts = op.path.split('/').slice(1).map(unescapePointer);
        const last = parts.pop();
        let parent = doc;
        for (const p of parts) {
            parent = parent?.[Array.isArray(parent) ? Number(p) : p];
            if (parent === undefined) throw new Error(`${where}: ${op.op} ${op.path}: no such parent`);
        }
        if (op.op === 'add') {
            if (Array.isArray(parent)) parent.splice(last === '-' ? parent.length : Number(last), 0, op.value);
            else parent[last] = op.value;
        } else if (op.op === 'replace') {
            if (!(last in parent)) throw new Error(`${where}: replace ${op.path}: nothing there`);
            parent[last] = op.value;
        } else if (op.op === 'remove') {
            if (!(last in parent)) throw new Error(`${where}: remove ${op.path}: nothing there`);
            if (Array.isArray(parent)) parent.splice(Number(last), 1);
            else delete parent[last];
        } else {
            throw new Error(`${where}: patch op '${op.op}' is not supported here`);
        }
    }
}

const CLUSTER_SCOPED = new Set(['Namespace', 'ClusterRole', 'ClusterRoleBinding', 'PersistentVolume', 'StorageClass']);
const KUSTOMIZATION_FIELDS = new Set(['apiVersion', 'kind', 'namespace', 'resources', 'images', 'patches']);

function podSpecs(doc) {
    if (doc.kind === 'Deployment' || doc.kind === 'Job') return [doc.spec?.template?.spec].filter(Boolean);
    return [];
}

/** kustomize build for the subset these manifests use; throws on anything else. */
function build(dir) {
    const file = path.join(dir, 'kustomization.yaml');
    const k = parseYaml(readFileSync(file, 'utf8'));
    const unsupported = Object.keys(k).filter((key) => !KUSTOMIZATION_FIELDS.has(key));
    if (unsupported.length) throw new Error(`${file}: fields this validator cannot build: ${unsupported.join(', ')}`);
    if (k.kind !== 'Kustomization') throw new Error(`${file}: kind must be Kustomization`);
    let docs = [];
    for (const r of k.resources ?? []) {
        const p = path.resolve(dir, r);
        if (!existsSync(p)) throw new Error(`${file}: resource ${r} does not exist`);
        docs.push(...(statSync(p).isDirectory() ? build(p) : readDocs(p)));
    }
    docs = structuredClone(docs);
    for (const patch of k.patches ?? []) {
        const t = patch.target ?? {};
        const targets = docs.filter((d) => d.kind === t.kind && (!t.name || d.metadata?.name === t.name)
            && (!t.version || d.apiVersion.split('/').at(-1) === t.version)
            && (!t.group || d.apiVersion.split('/')[0] === t.group));
        if (!targets.length) throw new Error(`${file}: a patch matches nothing (${JSON.stringify(t)})`);
        for (const d of targets) applyJsonPatch(d, parseYaml(patch.patch), `${file} -> ${describe(d)}`);
    }
    if (k.namespace)
        for (const d of docs) if (!CLUSTER_SCOPED.has(d.kind)) (d.metadata ??= {}).namespace = k.namespace;
    for (const image of k.images ?? []) {
        let used = false;
        for (const spec of docs.flatMap(podSpecs))
            for (const c of [...(spec.containers ?? []), ...(spec.initContainers ?? [])]) {
                if (c.image.split(':')[0] !== image.name) continue;
                c.image = `${image.newName ?? image.name}:${image.newTag ?? c.image.split(':')[1] ?? 'latest'}`;
                used = true;
            }
        if (!used) throw new Error(`${file}: image ${image.name} is not used`);
    }
    return docs;
}

// ---- consistency checks over one build -------------------------------------------------------------

function serverEnvironment() {
    const names = new Set();
    const walk = (dir) => {
        for (const name of readdirSync(dir)) {
            const p = path.join(dir, name);
            if (statSync(p).isDirectory()) walk(p);
            else if (/\.(cpp|h)$/.test(name)) for (const m of readFileSync(p, 'utf8').matchAll(/"(GI_[A-Z0-9_]+)"/g)) names.add(m[1]);
        }
    };
    walk(path.join(REPO, 'server'));
    return names;
}
const SERVER_ENV = serverEnvironment();
const IMAGE_UID = Number(readFileSync(path.join(REPO, 'deploy/container/steps.sh'), 'utf8').match(/^GI_UID=(\d+)$/m)?.[1]);
const requestSchema = new Ajv2020({ allErrors: true, strict: false })
    .compile(JSON.parse(readFileSync(path.join(REPO, 'protocol/http/render_request.json'), 'utf8')));

function adapterMetrics() {
    const names = new Set();
    for (const file of yamlFiles(path.join(ROOT, 'monitoring'))) {
        for (const doc of readDocs(file)) {
            const config = doc.kind === 'ConfigMap' && doc.data?.['config.yaml'];
            if (!config) continue;
            const rules = parseYaml(config)?.rules;
            if (!Array.isArray(rules) || !rules.length) {
                fail(`${path.relative(ROOT, file)}`, 'config.yaml has no rules');
                continue;
            }
            for (const [i, r] of rules.entries()) {
                const missing = ['seriesQuery', 'resources', 'name', 'metricsQuery'].filter((f) => !r[f]);
                if (missing.length) fail(`${path.relative(ROOT, file)} rule ${i}`, `missing ${missing.join(', ')}`);
                else if (!r.resources.overrides?.pod || !r.resources.overrides?.namespace)
                    fail(`${path.relative(ROOT, file)} rule ${i}`, 'per-pod metrics need the namespace and pod overrides');
                else names.add(r.name.as);
            }
        }
    }
    return names;
}

function matches(selector, labels) {
    return Object.entries(selector ?? {}).every(([k, v]) => labels?.[k] === v);
}

function checkBuild(name, docs) {
    const where = (doc) => `${name} ${describe(doc)}`;
    const byKind = (kind) => docs.filter((d) => d.kind === kind);
    const configMaps = new Map(byKind('ConfigMap').map((c) => [c.metadata.name, c]));
    const served = adapterMetrics();

    for (const doc of docs) {
        for (const spec of podSpecs(doc)) {
            if (spec.securityContext?.runAsUser !== IMAGE_UID)
                fail(where(doc), `runAsUser ${spec.securityContext?.runAsUser} is not the image's user ${IMAGE_UID} (deploy/container/steps.sh)`);
            for (const c of spec.containers) {
                const env = new Map();
                for (const from of c.envFrom ?? []) {
                    const cm = configMaps.get(from.configMapRef?.name);
                    if (!cm && !from.configMapRef?.optional) fail(where(doc), `envFrom ConfigMap ${from.configMapRef?.name} is not in this build`);
                    for (const [k, v] of Object.entries(cm?.data ?? {})) env.set(k, v);
                }
                for (const e of c.env ?? []) env.set(e.name, e.value);
                const unknown = [...env.keys()].filter((k) => k.startsWith('GI_') && !SERVER_ENV.has(k));
                if (unknown.length) fail(where(doc), `variables gi-server does not read: ${unknown.join(', ')}`);
                if (doc.kind !== 'Deployment') continue;
                for (const probe of ['readinessProbe', 'livenessProbe', 'startupProbe'])
                    if (c[probe]?.httpGet?.path !== '/healthz') fail(where(doc), `${probe} must GET /healthz`);
                const grace = spec.terminationGracePeriodSeconds ?? 30;
                const drain = Number(env.get('GI_DRAIN_SECONDS') ?? 20);
                const preStop = c.lifecycle?.preStop?.exec?.command;
                const delay = preStop?.[0] === 'sleep' ? Number(preStop[1]) : 0;
                if (delay + drain + 5 > grace)
                    fail(where(doc), `preStop ${delay} s + drain ${drain} s + 5 s teardown exceed terminationGracePeriodSeconds ${grace}`);
                const live = c.livenessProbe ?? {};
                if ((live.periodSeconds ?? 10) * (live.failureThreshold ?? 3) <= grace)
                    fail(where(doc), 'liveness could restart a draining pod (/healthz is 503): periodSeconds x failureThreshold must exceed the grace period');
                const port = c.ports?.find((p) => p.name === 'http')?.containerPort;
                if (String(port) !== String(env.get('GI_PORT') ?? 8080)) fail(where(doc), `port http ${port} is not GI_PORT ${env.get('GI_PORT')}`);
                if (!c.resources?.requests?.cpu || !c.resources?.requests?.memory || !c.resources?.limits?.memory)
                    fail(where(doc), 'needs CPU and memory requests and a memory limit');
            }
        }
    }
    const templates = byKind('Deployment').map((d) => ({ d, labels: d.spec.template.metadata.labels, ports: d.spec.template.spec.containers.flatMap((c) => c.ports ?? []) }));
    for (const s of byKind('Service')) {
        const t = templates.find((x) => matches(s.spec.selector, x.labels));
        if (!t) fail(where(s), 'selects no Deployment of this build');
        else for (const p of s.spec.ports) if (typeof p.targetPort === 'string' && !t.ports.some((q) => q.name === p.targetPort))
            fail(where(s), `targetPort ${p.targetPort} is not a container port of ${describe(t.d)}`);
    }
    for (const ing of byKind('Ingress')) {
        for (const rule of ing.spec.rules ?? []) for (const p of rule.http?.paths ?? []) {
            const svc = byKind('Service').find((s) => s.metadata.name === p.backend.service?.name);
            if (!svc) fail(where(ing), `backend service ${p.backend.service?.name} is not in this build`);
            else if (p.backend.service.port.name && !svc.spec.ports.some((q) => q.name === p.backend.service.port.name))
                fail(where(ing), `service port ${p.backend.service.port.name} does not exist`);
        }
        if (ing.metadata.annotations?.['nginx.ingress.kubernetes.io/affinity'] !== 'cookie')
            fail(where(ing), 'sessions are stateful: cookie affinity is required');
    }
    for (const pdb of byKind('PodDisruptionBudget'))
        if (!templates.some((t) => matches(pdb.spec.selector.matchLabels, t.labels))) fail(where(pdb), 'selects no Deployment of this build');
    for (const hpa of byKind('HorizontalPodAutoscaler')) {
        const ref = hpa.spec.scaleTargetRef;
        if (!docs.some((d) => d.kind === ref.kind && d.metadata.name === ref.name)) fail(where(hpa), `target ${ref.kind} ${ref.name} is not in this build`);
        for (const m of hpa.spec.metrics ?? [])
            if (m.type === 'Pods' && !served.has(m.pods.metric.name))
                fail(where(hpa), `custom metric ${m.pods.metric.name} is not served by monitoring/prometheus-adapter-config.yaml`);
    }
    for (const job of byKind('Job')) {
        const volume = job.spec.template.spec.volumes?.find((v) => v.configMap);
        const cm = volume && configMaps.get(volume.configMap.name);
        if (!cm) {
            fail(where(job), 'no requests ConfigMap in this build');
            continue;
        }
        const keys = Object.keys(cm.data ?? {}).sort();
        const expected = Array.from({ length: job.spec.completions }, (_, i) => `${i}.json`).sort();
        if (JSON.stringify(keys) !== JSON.stringify(expected)) fail(where(job), `completions ${job.spec.completions} need keys ${expected.join(', ')}; the ConfigMap has ${keys.join(', ')}`);
        for (const key of keys) {
            let body;
            try {
                body = JSON.parse(cm.data[key]);
            } catch (e) {
                fail(`${where(cm)} ${key}`, `not JSON: ${e.message}`);
                continue;
            }
            if (!requestSchema(body)) fail(`${where(cm)} ${key}`, `not a valid render request: ${requestSchema.errors.map((e) => `${e.instancePath} ${e.message}`).join('; ')}`);
        }
    }
}

// ---- main ------------------------------------------------------------------------------------------

async function validateTree() {
    const files = yamlFiles(ROOT);
    for (const file of files.filter((f) => path.basename(f) !== 'kustomization.yaml'))
        await validateDocs(path.relative(ROOT, file), readDocs(file));
    for (const file of files.filter((f) => path.basename(f) === 'kustomization.yaml')) {
        const name = `build ${path.relative(ROOT, path.dirname(file))}`;
        let docs;
        try {
            docs = build(path.dirname(file));
        } catch (e) {
            fail(name, e.message);
            continue;
        }
        await validateDocs(name, docs);
        const before = failures;
        checkBuild(name, docs);
        if (failures === before) pass(name, `${docs.length} objects consistent`);
    }
    if (!files.length) fail(ROOT, 'no manifests');
}

/** The checks must catch what they claim to: each mutation of a valid Deployment must fail. */
async function runSelfTest() {
    const deployment = readDocs(path.join(ROOT, 'base/deployment.yaml'))[0];
    const cases = [
        ['a misspelt field', (d) => { d.spec.template.spec.containers[0].readinessprobe = {}; }, /unknown field .*readinessprobe/],
        ['a misspelt nested field', (d) => { d.spec.strategy.rollingUpdate.maxSurges = 1; }, /unknown field .*maxSurges/],
        ['a wrong type', (d) => { d.spec.replicas = 'two'; }, /replicas must be integer/],
        ['a missing required field', (d) => { delete d.spec.selector; }, /required property .*selector/],
        ['a bad quantity', (d) => { d.spec.template.spec.containers[0].resources.limits.memory = 'lots'; }, /quantity/],
    ];
    for (const [what, mutate, expected] of cases) {
        const d = structuredClone(deployment);
        mutate(d);
        const problems = (await schemaProblems(d)).join('; ');
        if (expected.test(problems)) pass('self-test', `${what} is reported (${problems.slice(0, 100)})`);
        else fail('self-test', `${what} was not reported as ${expected}: '${problems}'`);
    }
    const clean = await schemaProblems(deployment);
    if (clean.length) fail('self-test', `the unmodified Deployment fails: ${clean.join('; ')}`);
    else pass('self-test', 'the unmodified Deployment passes');
}

if (selfTest) await runSelfTest();
await validateTree();
console.log(`${passes} passed, ${failures} failed`);
process.exit(failures ? 1 : 0);
