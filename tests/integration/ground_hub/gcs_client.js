// A ground station as QGroundControl behaves on connect, written with node-mavlink (an independent MAVLink
// implementation): it listens on a UDP port (QGroundControl: 14550) and answers whoever sends the vehicle's
// MAVLink there (listen:PORT), or sends to HOST:PORT first; it sends its own HEARTBEAT as a GCS once a
// second, measures the vehicle's HEARTBEAT and GLOBAL_POSITION_INT rates, downloads every parameter
// (PARAM_REQUEST_LIST, then PARAM_REQUEST_READ by index for what is missing), downloads the mission
// (MISSION_REQUEST_LIST, MISSION_REQUEST_INT per item, MISSION_ACK) and changes the mode (COMMAND_LONG
// MAV_CMD_DO_SET_MODE, then the next heartbeats must show it). Prints one JSON summary line.
//   node gcs_client.js listen:PORT|HOST:PORT NODE_MODULES_DIR MODE_NUMBER
'use strict';
const dgram = require('dgram');
const path = require('path');

const [target, modules, modeArg] = process.argv.slice(2);
if (!target || !modules || modeArg === undefined) {
    console.error('usage: node gcs_client.js listen:PORT|HOST:PORT NODE_MODULES_DIR MODE_NUMBER');
    process.exit(2);
}
let mavlink;
try {
    mavlink = require(path.join(modules, 'node-mavlink'));
} catch (e) {
    console.error(`gcs_client: node-mavlink is not installed in ${modules}; run ` +
                  `tests/integration/mavlink_interop/setup.sh ${path.resolve(modules, '..', '..')}`);
    process.exit(1);
}
const { minimal, common, ardupilotmega, MavLinkProtocolV2, MavLinkPacketSplitter, MavLinkPacketParser } = mavlink;
const REGISTRY = { ...minimal.REGISTRY, ...common.REGISTRY, ...ardupilotmega.REGISTRY };
const BY_NAME = Object.fromEntries(Object.values(REGISTRY).map(c => [c.MSG_NAME, c]));
const make = name => new BY_NAME[name]();
const wantedMode = Number(modeArg);
const listening = target.startsWith('listen:');
// Where our frames go: HOST:PORT, or (listening) wherever the vehicle's frames come from.
let [host, port] = [target.slice(0, target.lastIndexOf(':')), Number(target.slice(target.lastIndexOf(':') + 1))];
const bindPort = listening ? port : 0;
let peerKnown = !listening;

const GCS_SYSID = 255;
const GCS_COMPID = 190;
const protocol = new MavLinkProtocolV2(GCS_SYSID, GCS_COMPID);
const socket = dgram.createSocket('udp4');
let seq = 0;
function send(msg) {
    if (peerKnown) {
        socket.send(protocol.serialize(msg, seq++ % 256), port, host);
    }
}

const started = Date.now();
const since = () => (Date.now() - started) / 1000;
const result = {
    heartbeats: [], positions: [], params: { count: null, received: 0, rerequested: 0 },
    mission: { count: null, received: 0 }, mode: { ack: null, seen: false }, statustexts: [],
};
let vehicle = null;  // { sysid, compid }
const params = new Map();
const missionItems = new Map();
const waiters = [];  // { match(packet, data) -> bool, resolve }

function waitFor(match, ms) {
    return new Promise(resolve => {
        const w = { match, resolve };
        waiters.push(w);
        setTimeout(() => {
            const i = waiters.indexOf(w);
            if (i >= 0) {
                waiters.splice(i, 1);
                resolve(null);
            }
        }, ms);
    });
}

const splitter = new MavLinkPacketSplitter({}, { onCrcError: () => {} });
const parser = new MavLinkPacketParser();
splitter.pipe(parser);
socket.on('message', (buffer, rinfo) => {
    if (!peerKnown) {
        [host, port, peerKnown] = [rinfo.address, rinfo.port, true];
    }
    splitter.write(buffer);
});
parser.on('data', packet => {
    const clazz = REGISTRY[packet.header.msgid];
    if (!clazz) {
        return;
    }
    const data = packet.protocol.data(packet.payload, clazz);
    const name = clazz.MSG_NAME;
    const h = packet.header;
    if (name === 'HEARTBEAT' && data.type !== 6) {
        if (!vehicle) {
            vehicle = { sysid: h.sysid, compid: h.compid };
        }
        if (h.sysid === vehicle.sysid && h.compid === vehicle.compid) {
            result.heartbeats.push(since());
            if (data.customMode === wantedMode && result.mode.ack === 0) {
                result.mode.seen = true;
            }
        }
    } else if (name === 'GLOBAL_POSITION_INT') {
        result.positions.push(since());
    } else if (name === 'PARAM_VALUE') {
        result.params.count = data.paramCount;
        params.set(data.paramIndex, data.paramValue);
    } else if (name === 'MISSION_ITEM_INT' && h.sysid === (vehicle && vehicle.sysid)) {
        missionItems.set(data.seq, data);
    } else if (name === 'STATUSTEXT') {
        result.statustexts.push(String(data.text).replace(/\0.*$/, ''));
    }
    for (const w of [...waiters]) {
        if (w.match(name, data, h)) {
            waiters.splice(waiters.indexOf(w), 1);
            w.resolve({ name, data, header: h });
        }
    }
});

function heartbeat() {
    const hb = make('HEARTBEAT');
    hb.type = 6;        // MAV_TYPE_GCS
    hb.autopilot = 8;   // MAV_AUTOPILOT_INVALID
    hb.baseMode = 0;
    hb.customMode = 0;
    hb.systemStatus = 4;  // MAV_STATE_ACTIVE
    hb.mavlinkVersion = 3;
    send(hb);
}

function rate(times) {
    // Over the last 10 s of the run: what an operator sees now, not the start-up.
    const end = since();
    const recent = times.filter(t => t >= end - 10);
    return recent.length / Math.min(10, end);
}

async function downloadParams() {
    const list = make('PARAM_REQUEST_LIST');
    list.targetSystem = vehicle.sysid;
    list.targetComponent = vehicle.compid;
    send(list);
    let lastCount = -1;
    for (let idle = 0; idle < 40;) {
        await new Promise(r => setTimeout(r, 1000));
        const count = result.params.count;
        if (count !== null && params.size >= count) {
            return true;
        }
        if (params.size === lastCount) {
            idle += 1;
            // Quiet for 2 s: ask for the missing ones by index, as QGroundControl does.
            if (count !== null && idle % 2 === 0) {
                for (let i = 0, asked = 0; i < count && asked < 10; i++) {
                    if (!params.has(i)) {
                        const read = make('PARAM_REQUEST_READ');
                        read.targetSystem = vehicle.sysid;
                        read.targetComponent = vehicle.compid;
                        read.paramId = '';
                        read.paramIndex = i;
                        send(read);
                        asked += 1;
                        result.params.rerequested += 1;
                    }
                }
            }
        } else {
            idle = 0;
        }
        lastCount = params.size;
    }
    return false;
}

async function downloadMission() {
    let count = null;
    for (let attempt = 0; attempt < 5 && count === null; attempt++) {
        const list = make('MISSION_REQUEST_LIST');
        list.targetSystem = vehicle.sysid;
        list.targetComponent = vehicle.compid;
        list.missionType = 0;
        send(list);
        const answer = await waitFor((name, d, h) => name === 'MISSION_COUNT' && h.sysid === vehicle.sysid &&
                                     d.targetSystem === GCS_SYSID, 3000);
        if (answer) {
            count = answer.data.count;
        }
    }
    result.mission.count = count;
    if (count === null) {
        return false;
    }
    for (let s = 0; s < count; s++) {
        for (let attempt = 0; attempt < 5 && !missionItems.has(s); attempt++) {
            const request = make('MISSION_REQUEST_INT');
            request.targetSystem = vehicle.sysid;
            request.targetComponent = vehicle.compid;
            request.seq = s;
            request.missionType = 0;
            send(request);
            await waitFor((name, d) => name === 'MISSION_ITEM_INT' && d.seq === s, 3000);
        }
        if (!missionItems.has(s)) {
            return false;
        }
    }
    result.mission.received = missionItems.size;
    const ack = make('MISSION_ACK');
    ack.targetSystem = vehicle.sysid;
    ack.targetComponent = vehicle.compid;
    ack.type = 0;  // MAV_MISSION_ACCEPTED
    ack.missionType = 0;
    send(ack);
    return true;
}

async function setMode() {
    for (let attempt = 0; attempt < 5 && result.mode.ack === null; attempt++) {
        const cmd = make('COMMAND_LONG');
        cmd.targetSystem = vehicle.sysid;
        cmd.targetComponent = vehicle.compid;
        cmd.command = 176;  // MAV_CMD_DO_SET_MODE
        cmd.confirmation = attempt;
        cmd._param1 = 1;    // MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        cmd._param2 = wantedMode;
        cmd._param3 = 0; cmd._param4 = 0; cmd._param5 = 0; cmd._param6 = 0; cmd._param7 = 0;
        send(cmd);
        const ack = await waitFor((name, d) => name === 'COMMAND_ACK' && d.command === 176, 3000);
        if (ack) {
            result.mode.ack = ack.data.result;
        }
    }
    for (let i = 0; i < 100 && !result.mode.seen; i++) {
        await new Promise(r => setTimeout(r, 100));
    }
    return result.mode.ack === 0 && result.mode.seen;
}

async function main() {
    await new Promise((resolve, reject) => {
        socket.once('error', reject);
        socket.bind(bindPort, '127.0.0.1', resolve);
    });
    heartbeat();
    const beating = setInterval(heartbeat, 1000);
    for (let i = 0; i < 300 && !vehicle; i++) {
        await new Promise(r => setTimeout(r, 100));
    }
    const problems = [];
    if (!vehicle) {
        problems.push('no heartbeat from the vehicle within 30 s');
    } else {
        if (!await downloadParams()) problems.push(`parameters: ${params.size} of ${result.params.count}`);
        result.params.received = params.size;
        if (!await downloadMission()) problems.push(`mission: ${missionItems.size} of ${result.mission.count}`);
        if (!await setMode()) problems.push(`mode ${wantedMode}: ack ${result.mode.ack}, seen ${result.mode.seen}`);
    }
    clearInterval(beating);
    const summary = {
        ok: problems.length === 0, problems, seconds: since(), vehicle,
        heartbeat_hz: rate(result.heartbeats), position_hz: rate(result.positions),
        params: result.params, mission: result.mission, mode: result.mode, statustexts: result.statustexts,
    };
    console.log(JSON.stringify(summary));
    socket.close();
    process.exit(summary.ok ? 0 : 1);
}

main().catch(e => {
    console.error(e);
    process.exit(1);
});
