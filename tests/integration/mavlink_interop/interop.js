// Checks airseg-mavdump against node-mavlink, an independent MAVLink implementation:
//  1. frames that node-mavlink serializes (v1 and v2, signed or not) decode through airseg-mavdump field for
//     field to the values node-mavlink was given;
//  2. JSON lines with the same values, turned into frames by airseg-mavdump --encode, are accepted by
//     node-mavlink's splitter (checksum with its own CRC_EXTRA table) and deserialize to the same values.
// Every message of the dialect airseg-mavdump knows (airseg-mavdump --messages: ArduPilot's whole dialect) is
// covered, with seeded random values across each type's full range. A message node-mavlink does not define
// with the same id and CRC_EXTRA (newer definitions than its own) is still round-tripped through
// airseg-mavdump --encode and back, and reported as not cross-checked.
//   node interop.js PATH/TO/airseg-mavdump PATH/TO/node_modules
'use strict';
const path = require('path');
const { spawnSync } = require('child_process');

const [mavdump, modules] = process.argv.slice(2);
if (!mavdump || !modules) {
    console.error('usage: node interop.js AIRSEG_MAVDUMP NODE_MODULES_DIR');
    process.exit(2);
}
let mavlink;
try {
    mavlink = require(path.join(modules, 'node-mavlink'));
} catch (e) {
    console.error(`mavlink_interop: node-mavlink is not installed in ${modules}.\n` +
                  `Run: tests/integration/mavlink_interop/setup.sh ${path.resolve(modules, "..", "..")}`);
    process.exit(1);
}
const { minimal, common, ardupilotmega, MavLinkProtocolV1, MavLinkProtocolV2, MavLinkPacketSplitter,
        MavLinkPacketParser, MavLinkPacketSignature } = mavlink;

const registry = {};
for (const dialect of Object.values(mavlink).filter(d => d && typeof d === 'object' && d.REGISTRY)) {
    for (const clazz of Object.values(dialect.REGISTRY)) registry[clazz.MSG_NAME] = registry[clazz.MSG_NAME] || clazz;
}

// Seeded PRNG (mulberry32): the same values on every run.
let state = 0x5eed1234;
function rand() {
    state = (state + 0x6D2B79F5) >>> 0;
    let t = state;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
}
const randInt = (lo, hi) => lo + Math.floor(rand() * (hi - lo + 1));
function randBig(bits, signed) {
    let v = 0n;
    for (let i = 0; i < bits; i += 16) v = (v << 16n) | BigInt(randInt(0, 0xffff));
    v &= (1n << BigInt(bits)) - 1n;
    return signed ? BigInt.asIntN(bits, v) : v;
}
function randFloat() {
    const r = rand();
    if (r < 0.05) return NaN;
    if (r < 0.1) return 0;
    const f = new Float32Array(1);
    f[0] = (rand() - 0.5) * Math.pow(10, randInt(-20, 20));
    return f[0];
}
function baseType(type) { return type.replace('[]', '').replace('_mavlink_version', ''); }
function randScalar(type) {
    switch (baseType(type)) {
        case 'uint8_t': return randInt(0, 0xff);
        case 'int8_t': return randInt(-0x80, 0x7f);
        case 'uint16_t': return randInt(0, 0xffff);
        case 'int16_t': return randInt(-0x8000, 0x7fff);
        case 'uint32_t': return randInt(0, 0xffffffff);
        case 'int32_t': return randInt(-0x80000000, 0x7fffffff);
        case 'uint64_t': return randBig(64, false);
        case 'int64_t': return randBig(64, true);
        case 'float': return randFloat();
        case 'double': return (rand() - 0.5) * 1e10;
        default: throw new Error(`no generator for ${type}`);
    }
}
function randText(length) {
    // Printable ASCII without NUL (node-mavlink drops NULs anywhere in a string); sometimes the full length,
    // so that unterminated strings are covered.
    const n = rand() < 0.3 ? length : randInt(1, length);
    let s = '';
    for (let i = 0; i < n; i++) s += String.fromCharCode(randInt(0x20, 0x7e));
    return s;
}
// Values for one message; `sparse` leaves the trailing fields at zero so that v2 truncation is exercised.
function randomValues(spec, sparse) {
    const values = {};
    const fields = spec.FIELDS;
    const keep = sparse ? randInt(1, fields.length) : fields.length;
    fields.forEach((f, i) => {
        const zero = i >= keep;
        if (f.type === 'char[]') values[f.source] = zero ? '' : randText(f.length);
        else if (f.type.endsWith('[]')) values[f.source] = Array.from({ length: f.length }, () => zero ? zeroOf(f.type) : randScalar(f.type));
        else values[f.source] = zero ? zeroOf(f.type) : randScalar(f.type);
    });
    return values;
}
function zeroOf(type) { return baseType(type).endsWith('64_t') ? 0n : 0; }

// A message as airseg-mavdump --messages lists it, in the shape of a node-mavlink class (FIELDS in wire
// order: base fields by element size, stable, then extensions), for messages node-mavlink does not define.
const TYPE_SIZE = { char: 1, uint8_t: 1, int8_t: 1, uint16_t: 2, int16_t: 2, uint32_t: 4, int32_t: 4, float: 4,
                    uint64_t: 8, int64_t: 8, double: 8 };
function specOf(m) {
    const fields = m.fields.map(f => ({ source: f.name, name: f.name, type: f.type + (f.length ? '[]' : ''),
                                        length: f.length || 0, extension: Boolean(f.extension) }));
    const base = fields.filter(f => !f.extension);
    const wire = base.map((f, i) => [f, i]).sort((x, y) => TYPE_SIZE[baseType(y[0].type)] - TYPE_SIZE[baseType(x[0].type)] || x[1] - y[1])
                     .map(x => x[0]);
    return { MSG_ID: m.msgid, MSG_NAME: m.name, MAGIC_NUMBER: m.crc_extra, FIELDS: wire.concat(fields.filter(f => f.extension)) };
}

function toNodeMessage(clazz, values) {
    const msg = new clazz();
    for (const f of clazz.FIELDS) msg[f.name] = values[f.source];
    return msg;
}

// airseg-mavdump's JSON, with integers beyond 2^53 kept exact as BigInt.
function parseJsonLine(line) {
    // Marked with U+0001, which the generated strings (printable ASCII) never hold.
    const quoted = line.replace(/([:\[,])(-?\d{16,})(?=[,\]}])/g, '$1"\\u0001$2"');
    return JSON.parse(quoted, (k, v) => (typeof v === 'string' && /^\u0001-?\d+$/.test(v) ? BigInt(v.slice(1)) : v));
}
// Values as airseg-mavdump writes them in JSON.
function toJsonValue(type, v) {
    if (typeof v === 'bigint') return v.toString();
    if (typeof v === 'number' && baseType(type) === 'float') {
        if (Number.isNaN(v)) return '"nan"';
        if (!Number.isFinite(v)) return v > 0 ? '"inf"' : '"-inf"';
    }
    if (Array.isArray(v)) return '[' + v.map(x => toJsonValue(type, x)).join(',') + ']';
    return JSON.stringify(v);
}

const show = v => JSON.stringify(v, (k, x) => (typeof x === 'bigint' ? x.toString() : x));
let failures = 0;
function fail(msg) {
    failures++;
    if (failures <= 30) console.error('MISMATCH ' + msg);
}
function sameScalar(type, expected, actual) {
    const t = baseType(type);
    if (t === 'float' || t === 'double') {
        if (actual === 'nan') actual = NaN;
        if (actual === 'inf') actual = Infinity;
        if (actual === '-inf') actual = -Infinity;
        if (Number.isNaN(expected)) return Number.isNaN(actual);
        // airseg writes the shortest text that reads back as the same float32.
        return t === 'float' ? typeof actual === 'number' && Math.fround(expected) === Math.fround(actual)
                             : expected === actual;
    }
    if (typeof expected === 'bigint' || typeof actual === 'bigint') return BigInt(expected) === BigInt(actual);
    return expected === actual;
}
function compareField(where, f, expected, actual) {
    if (f.type === 'char[]') {
        if (expected !== actual) fail(`${where}.${f.source}: expected ${show(expected)}, got ${show(actual)}`);
    } else if (f.type.endsWith('[]')) {
        if (!Array.isArray(actual) || actual.length !== expected.length) {
            fail(`${where}.${f.source}: expected an array of ${expected.length}, got ${show(actual)}`);
            return;
        }
        expected.forEach((e, i) => {
            if (!sameScalar(f.type, e, actual[i])) fail(`${where}.${f.source}[${i}]: expected ${e}, got ${actual[i]}`);
        });
    } else if (!sameScalar(f.type, expected, actual)) {
        fail(`${where}.${f.source}: expected ${expected}, got ${actual}`);
    }
}
function expectedFor(clazz, values, version) {
    // MAVLink 1 as airseg sends it carries no extension fields: they arrive as zero.
    if (version !== 1) return values;
    const out = { ...values };
    for (const f of clazz.FIELDS) {
        if (!f.extension) continue;
        out[f.source] = f.type === 'char[]' ? '' : f.type.endsWith('[]') ? f.length && Array(f.length).fill(zeroOf(f.type)) : zeroOf(f.type);
    }
    return out;
}

function runMavdump(args, input) {
    const r = spawnSync(mavdump, args, { input, maxBuffer: 64 * 1024 * 1024 });
    if (r.error) throw r.error;
    return r;
}

async function nodeDecode(bytes) {
    const splitter = new MavLinkPacketSplitter({}, { onCrcError: () => {} });
    const parser = new MavLinkPacketParser();
    const packets = [];
    const done = new Promise((resolve, reject) => {
        parser.on('data', p => packets.push(p));
        parser.on('end', resolve);
        parser.on('error', reject);
    });
    splitter.pipe(parser);
    splitter.end(bytes);
    await done;
    return { packets, valid: splitter.validPackages, invalid: splitter.invalidPackages, unknown: splitter.unknownPackagesCount };
}

// The dialect airseg-mavdump decodes, split into the messages node-mavlink defines identically (same id and
// CRC_EXTRA; it may lack extension fields added since) and those it does not.
function dialect() {
    const r = runMavdump(['--messages'], '');
    if (r.status !== 0) throw new Error(`airseg-mavdump --messages exited ${r.status}: ${r.stderr}`);
    const messages = r.stdout.toString().split('\n').filter(l => l.length > 0).map(l => JSON.parse(l));
    const shared = [];
    const ownOnly = [];
    for (const m of messages) {
        const clazz = registry[m.name];
        if (clazz && clazz.MSG_ID === m.msgid && clazz.MAGIC_NUMBER === m.crc_extra) {
            const missing = m.fields.filter(f => !clazz.FIELDS.some(g => g.source === f.name));
            if (missing.some(f => !f.extension)) fail(`${m.name}: node-mavlink lacks base fields ${missing.map(f => f.name)}`);
            shared.push({ name: m.name, clazz, own: m });
        } else {
            ownOnly.push({ name: m.name, clazz: specOf(m), own: m });
        }
    }
    return { messages, shared, ownOnly };
}

function makeCases(list, rounds, start) {
    const cases = [];
    for (let round = 0; round < rounds; round++) {
        for (const { name, clazz, own } of list) {
            cases.push({ name, clazz, own, values: randomValues(clazz, round % 3 === 2), version: round % 4 === 1 && clazz.MSG_ID < 256 ? 1 : 2,
                         signed: round % 4 === 3, seq: (start + cases.length) % 256, sysid: randInt(1, 255), compid: randInt(0, 255) });
        }
    }
    return cases;
}

// airseg-mavdump's decoding of frames built from `cases`, checked field for field against their values.
function checkDecoded(label, cases, bytes, expectedOf) {
    const decoded = runMavdump([], bytes);
    const lines = decoded.stdout.toString().split('\n').filter(l => l.length > 0);
    if (lines.length !== cases.length) fail(`${label}: ${cases.length} frames in, ${lines.length} JSON lines out; stderr: ${decoded.stderr}`);
    lines.slice(0, cases.length).forEach((line, i) => {
        const c = cases[i];
        const where = `${label} #${i} ${c.name} v${c.version}${c.signed ? ' signed' : ''}`;
        const j = parseJsonLine(line);
        if (j.name !== c.name || j.msgid !== c.clazz.MSG_ID || j.sysid !== c.sysid || j.compid !== c.compid ||
            j.seq !== c.seq || j.v !== c.version || Boolean(j.signed) !== c.signed || !j.fields) {
            fail(`${where}: header ${line.slice(0, 120)}`);
            return;
        }
        const expected = expectedOf(c);
        for (const f of c.clazz.FIELDS) compareField(where, f, expected[f.source], j.fields[f.source]);
        // Extension fields added after node-mavlink's definitions: not sent by it, so zero.
        for (const f of c.own.fields) {
            if (c.clazz.FIELDS.some(g => g.source === f.name)) continue;
            const zero = f.type === 'char' && f.length ? '' : f.length ? Array(f.length).fill(0) : 0;
            if (show(j.fields[f.name]) !== show(zero)) fail(`${where}: ${f.name} expected zero, got ${show(j.fields[f.name])}`);
        }
        const extra = Object.keys(j.fields).filter(k => !c.own.fields.some(f => f.name === k));
        if (extra.length) fail(`${where}: fields the dialect does not list: ${extra}`);
    });
    const summary = decoded.stderr.toString();
    if (!summary.includes(`"frames_ok":${cases.length},`) || !summary.includes('"bad_checksum":0,') ||
        !summary.includes('"unknown_msgid":0,')) fail(`${label} summary: ${summary}`);
    if (!summary.includes(`"signed_frames":${cases.filter(c => c.signed).length},`)) fail(`${label} signed count: ${summary}`);
}

function jsonLines(cases) {
    return cases.map(c => {
        const fields = c.clazz.FIELDS.map(f => `"${f.source}":${toJsonValue(f.type, c.values[f.source])}`).join(',');
        return `{"name":"${c.name}","sysid":${c.sysid},"compid":${c.compid},"seq":${c.seq},"v":${c.version},"fields":{${fields}}}`;
    }).join('\n') + '\n';
}

async function main() {
    const key = MavLinkPacketSignature.key('airseg interop');
    const { messages, shared, ownOnly } = dialect();
    if (messages.length < 300 || shared.length < 250) fail(`dialect: ${messages.length} messages, ${shared.length} shared with node-mavlink`);
    const cases = makeCases(shared, 12, 0);

    // 1. node-mavlink -> airseg-mavdump
    const chunks = cases.map(c => {
        const protocol = c.version === 1 ? new MavLinkProtocolV1(c.sysid, c.compid)
                                         : new MavLinkProtocolV2(c.sysid, c.compid, c.signed ? MavLinkProtocolV2.IFLAG_SIGNED : 0);
        const frame = protocol.serialize(toNodeMessage(c.clazz, c.values), c.seq);
        return c.signed ? protocol.sign(frame, 1, key) : frame;
    });
    checkDecoded('decode', cases, Buffer.concat(chunks), c => c.values);

    // 2. airseg-mavdump --encode -> node-mavlink
    const encoded = runMavdump(['--encode'], jsonLines(cases));
    if (encoded.status !== 0) fail(`--encode exited ${encoded.status}: ${encoded.stderr}`);
    const result = await nodeDecode(encoded.stdout);
    if (result.invalid !== 0 || result.unknown !== 0) fail(`node-mavlink rejected frames: ${result.invalid} bad checksum, ${result.unknown} unknown`);
    if (result.packets.length !== cases.length) fail(`encode: ${cases.length} lines in, node-mavlink accepted ${result.packets.length} frames`);
    result.packets.slice(0, cases.length).forEach((p, i) => {
        const c = cases[i];
        const where = `encode #${i} ${c.name} v${c.version}`;
        const h = p.header;
        if (h.msgid !== c.clazz.MSG_ID || h.sysid !== c.sysid || h.compid !== c.compid || h.seq !== c.seq ||
            (c.version === 1) !== (p.protocol instanceof MavLinkProtocolV1)) {
            fail(`${where}: header ${JSON.stringify({ msgid: h.msgid, sysid: h.sysid, compid: h.compid, seq: h.seq })}`);
            return;
        }
        const data = p.protocol.data(p.payload, c.clazz);
        const expected = expectedFor(c.clazz, c.values, c.version);
        for (const f of c.clazz.FIELDS) compareField(where, f, expected[f.source], data[f.name]);
    });

    // 3. Messages node-mavlink does not define as airseg does: airseg-mavdump --encode, then airseg-mavdump.
    const own = makeCases(ownOnly, 12, cases.length);
    for (const c of own) c.signed = false;  // --encode writes unsigned frames
    const ownEncoded = runMavdump(['--encode'], jsonLines(own));
    if (ownEncoded.status !== 0) fail(`--encode (own) exited ${ownEncoded.status}: ${ownEncoded.stderr}`);
    checkDecoded('own', own, ownEncoded.stdout, c => expectedFor(c.clazz, c.values, c.version));

    const fieldCount = shared.reduce((n, m) => n + m.clazz.FIELDS.length, 0);
    if (failures) {
        console.error(`mavlink_interop: ${failures} mismatches`);
        process.exit(1);
    }
    console.log(`mavlink_interop: ${messages.length} dialect messages; ${shared.length} (${fieldCount} fields) in ` +
                `${cases.length} frames decoded field for field from node-mavlink and accepted back by it; ` +
                `${ownOnly.length} that node-mavlink does not define alike round-tripped through airseg-mavdump ` +
                `alone: ${ownOnly.map(m => m.name).join(' ')}`);
}

main().catch(e => { console.error(e); process.exit(1); });
