#!/usr/bin/env bash
# Regenerates the seed corpus fuzz/corpus/<target>/ from real files (../shared/data, config/) and
# from what romo itself writes (tiny simulated recordings, replay outputs, a stereo worker's
# clouds). Seeds are kept small (a few KB) so libFuzzer mutates them quickly.
# Usage: fuzz/make_corpus.sh [ROMO_BINARY]   (default: build/tools/romo)
set -euo pipefail
cd "$(dirname "$0")/.."
romo=$(realpath "${1:-build/tools/romo}")
data=${ROMO_SHARED_DATA:-../shared/data}
out=fuzz/corpus
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Recordings: images at 5 % and 10 % scale (39x29, 78x58), raw and PNG, with depth truth.
"$romo" sim --frames 2 --scale 0.05 --depth --threads 1 --out "$work/sim_raw.lcmlog" >/dev/null
"$romo" sim --frames 2 --scale 0.05 --png --threads 1 --out "$work/sim_png.lcmlog" >/dev/null
"$romo" sim --frames 2 --scale 0.1 --threads 1 --out "$work/sim_01.lcmlog" >/dev/null
"$romo" sim --frames 2 --scale 0.25 --threads 1 --out "$work/sim_q.lcmlog" >/dev/null
# Outputs to planning (obstacles, slots, status, pedestrian predictions) and one rig's cloud.
"$romo" replay "$work/sim_q.lcmlog" --out "$work/replay" --no-pictures --threads 1 >/dev/null
"$romo" stereo-worker --rig 0 --source "log://$work/sim_01.lcmlog" \
  --lcm-url "file://$work/rigcloud.lcmlog?mode=w" --frames 1 >/dev/null
# RGB-D: a 16x12 TUM-layout pair (colour gradient, depth 1-1.5 m) recorded raw and as PNG.
mkdir -p "$work/rgbd"
python3 - "$work/rgbd" <<'PY'
import struct, sys, zlib
def png(path, w, h, bitdepth, colortype, row):
    raw = b''.join(b'\x00' + row(y) for y in range(h))
    chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d))
    ihdr = struct.pack('>IIBBBBB', w, h, bitdepth, colortype, 0, 0, 0)
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', ihdr) + chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
d = sys.argv[1]
png(d + '/1.png', 16, 12, 8, 2, lambda y: bytes(v for x in range(16) for v in (x * 16, y * 20, (x + y) * 8)))
png(d + '/1_depth.png', 16, 12, 16, 0, lambda y: b''.join(struct.pack('>H', 5000 + 100 * x + 50 * y) for x in range(16)))
PY
"$romo" record --source "rgbd://$work/rgbd" --out "$work/rgbd_raw.lcmlog" >/dev/null
"$romo" record --source "rgbd://$work/rgbd" --png --out "$work/rgbd_png.lcmlog" >/dev/null

rm -rf "$out"
mkdir -p "$out"/{lcm_sensors,lcm_planning,lcm_ground_truth,lcm_predictions,recording,calibration_yaml,rig_yaml,atlas_yaml,object_functions_yaml,pcd,eth_ucy,sim_uri}

# Single messages out of the logs: the first event of each (log, channel) listed.
python3 - "$work" "$out" <<'PY'
import struct, sys
work, out = sys.argv[1], sys.argv[2]
def events(path):
    b = open(path, 'rb').read()
    pos = 0
    while pos + 28 <= len(b):
        sync, _, ts, clen, dlen = struct.unpack('>IqqII', b[pos:pos + 28])
        assert sync == 0xEDA1DA01, path
        ch = b[pos + 28:pos + 28 + clen].decode()
        yield ch, b[pos + 28 + clen:pos + 28 + clen + dlen], b[pos:pos + 28 + clen + dlen]
        pos += 28 + clen + dlen
picks = [
    ('sim_raw.lcmlog', 'ROMO_STEREO_RIG0', 'lcm_sensors/stereo_raw'),
    ('sim_png.lcmlog', 'ROMO_STEREO_RIG1', 'lcm_sensors/stereo_png'),
    ('sim_raw.lcmlog', 'ROMO_VEHICLE_STATE', 'lcm_sensors/vehicle_state'),
    ('sim_raw.lcmlog', 'ROMO_GNSS', 'lcm_sensors/gnss'),
    ('sim_raw.lcmlog', 'ROMO_CALIBRATION', 'lcm_sensors/calibration'),
    ('rgbd_raw.lcmlog', 'ROMO_RGBD', 'lcm_sensors/rgbd_raw'),
    ('rgbd_png.lcmlog', 'ROMO_RGBD', 'lcm_sensors/rgbd_png'),
    ('sim_raw.lcmlog', 'ROMO_GT_FRAME', 'lcm_ground_truth/frame'),
    ('sim_raw.lcmlog', 'ROMO_GT_DEPTH_RIG0', 'lcm_ground_truth/depth_rig0'),
    ('replay/outputs.lcmlog', 'ROMO_OBSTACLES', 'lcm_planning/obstacles'),
    ('replay/outputs.lcmlog', 'ROMO_PARKING_SLOTS', 'lcm_planning/parking_slots'),
    ('replay/outputs.lcmlog', 'ROMO_PERCEPTION_STATUS', 'lcm_planning/status'),
    ('rigcloud.lcmlog', 'ROMO_RIG_CLOUD0', 'lcm_planning/rig_cloud'),
    ('replay/outputs.lcmlog', 'ROMO_PEDESTRIAN_PREDICTIONS', 'lcm_predictions/predictions'),
]
for log, channel, name in picks:
    data = next(d for ch, d, _ in events(f'{work}/{log}') if ch == channel)
    open(f'{out}/{name}', 'wb').write(data)
# The calibration YAML a recording carries (scaled sample calibration), for the YAML target.
cal = next(d for ch, d, _ in events(f'{work}/sim_raw.lcmlog') if ch == 'ROMO_CALIBRATION')
n = struct.unpack('>i', cal[16:20])[0]
open(f'{out}/calibration_yaml/recorded_scaled.yaml', 'wb').write(cal[20:20 + n - 1])
# Recordings: a whole small one, RGB-D, the first three events, and one cut inside an event.
raw = [r for _, _, r in events(f'{work}/sim_png.lcmlog')]
open(f'{out}/recording/sim_png.lcmlog', 'wb').write(b''.join(raw))
open(f'{out}/recording/first3.lcmlog', 'wb').write(b''.join(raw[:3]))
open(f'{out}/recording/cut.lcmlog', 'wb').write(b''.join(raw[:2]) + raw[2][:len(raw[2]) // 2])
open(f'{out}/recording/rgbd.lcmlog', 'wb').write(open(f'{work}/rgbd_raw.lcmlog', 'rb').read())
PY

# YAML as shipped.
cp config/calibration/romo_sample.yaml "$out/calibration_yaml/"
cp config/rigs/*.yaml "$out/rig_yaml/"
cp config/atlas.yaml "$out/atlas_yaml/"
cp config/object_functions.yaml "$out/object_functions_yaml/"

# PCD: the first 16 points of PCL's lamppost.pcd as ascii, binary and binary_compressed (LZF
# literal runs, field-major as PCL stores it), plus a FLOAT64/intensity variant.
python3 - "$data/pcl/lamppost.pcd" "$out/pcd" <<'PY'
import struct, sys
src, out = sys.argv[1], sys.argv[2]
lines = open(src).read().splitlines()
start = next(i for i, l in enumerate(lines) if l.startswith('DATA')) + 1
pts = [tuple(float(v) for v in l.split()[:3]) for l in lines[start:start + 16]]
def header(fields, size, typ, data):
    n = len(pts)
    return (f"# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {' '.join(fields)}\n"
            f"SIZE {' '.join([str(size)] * len(fields))}\nTYPE {' '.join([typ] * len(fields))}\n"
            f"COUNT {' '.join(['1'] * len(fields))}\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
            f"POINTS {n}\nDATA {data}\n").encode()
xyz = ['x', 'y', 'z']
open(f'{out}/ascii.pcd', 'wb').write(header(xyz, 4, 'F', 'ascii') + ''.join(f'{x} {y} {z}\n' for x, y, z in pts).encode())
open(f'{out}/binary.pcd', 'wb').write(header(xyz, 4, 'F', 'binary') + b''.join(struct.pack('<3f', *p) for p in pts))
soa = b''.join(struct.pack('<f', p[k]) for k in range(3) for p in pts)
lzf = b''.join(bytes([len(soa[i:i + 32]) - 1]) + soa[i:i + 32] for i in range(0, len(soa), 32))
open(f'{out}/binary_compressed.pcd', 'wb').write(header(xyz, 4, 'F', 'binary_compressed') + struct.pack('<II', len(lzf), len(soa)) + lzf)
fields = ['x', 'y', 'z', 'intensity']
open(f'{out}/binary_f64_intensity.pcd', 'wb').write(header(fields, 8, 'F', 'binary') + b''.join(struct.pack('<4d', *p, 0.5) for p in pts))
PY

# ETH/UCY: the first 60 rows of two real files.
head -n 60 "$data/eth_ucy/biwi_hotel.txt" > "$out/eth_ucy/biwi_hotel_head.txt"
head -n 60 "$data/eth_ucy/crowds_zara01.txt" > "$out/eth_ucy/crowds_zara01_head.txt"

# Source URIs as the README documents them.
printf '%s' 'sim://parking?seed=3&frames=20&scale=0.5&depth=1' > "$out/sim_uri/sim_full"
printf '%s' 'sim://parking' > "$out/sim_uri/sim_plain"
printf '%s' 'sim://parking?aa=2&noise=1.5&threads=2&first=40&rate_hz=5&distortion=0&start_ns=0' > "$out/sim_uri/sim_options"
printf '%s' 'log://run.lcmlog?loop=1&pacing=realtime&seek_s=2.5' > "$out/sim_uri/log"
printf '%s' 'rgbd:///data/tum?depth_scale=5000&max_dt_s=0.02' > "$out/sim_uri/rgbd"
printf '%s' 'sim-manip://writing?seed=3&frames=60&width=320&height=240&fps=30&noise=1&transports=1' > "$out/sim_uri/sim_manip"
printf '%s' 'log://x.lcmlog?loop=0&pacing=fast&seek_s=0' > "$out/sim_uri/log_options"

du -sh "$out"/*
