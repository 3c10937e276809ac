#!/usr/bin/env bash
# Creates the seed corpora of the fuzz targets in fuzz/corpus/<target>/ from the real data in
# ../shared/data (or $SILLAGE_DATA): small files copied as they are, big ones cut to their
# first lines, images cropped to 16-32 px (TIFF, CCITT strips, JPEG) or re-encoded from a crop
# (PNG), track tables converted from the bead ground truth. Runs nothing else; needs bash, awk
# and python3 (standard library only). Existing corpora are kept (libFuzzer adds to them);
# `rm -r fuzz/corpus` first for a fresh start.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
data=${SILLAGE_DATA:-$here/../../shared/data}
corpus=$here/corpus
if [ ! -d "$data/bedload_beads_lafaye2018" ]; then
    echo "seed.sh: no data at $data; set SILLAGE_DATA to the shared data folder" >&2
    exit 1
fi
for target in frame_decode mot csv_tables tractrac_text parquet_tracks toml_config tune_http; do
    mkdir -p "$corpus/$target"
done
beads=$data/bedload_beads_lafaye2018

# --- MOTChallenge rows and seqinfo.ini ------------------------------------------------------
for seq in TUD-Campus ETH-Bahnhof KITTI-13 ADL-Rundle-6; do
    for role in gt det; do
        head -n 30 "$data/mot15_train_gt_det/$seq/$role/$role.txt" >"$corpus/mot/$seq-$role.txt"
    done
    cp "$data/mot15_train_gt_det/$seq/seqinfo.ini" "$corpus/mot/$seq-seqinfo.ini"
done
head -n 30 "$data/pets09_s2l1/gt/gt.txt" >"$corpus/mot/pets09-gt.txt"
cp "$data/pets09_s2l1/seqinfo.ini" "$corpus/mot/pets09-seqinfo.ini"
head -n 30 "$data/motmetrics_tud_reference/iotest/motchallenge.txt" >"$corpus/mot/motmetrics.txt"
head -n 30 "$data/motmetrics_tud_reference/TUD-Campus/test.txt" >"$corpus/mot/motmetrics-test.txt"

# --- CSV tables: bead truth, detections, truth, CSV tracks, matrix --------------------------
truth=$beads/ground_truth/trackdatatruth.csv
head -n 40 "$truth" >"$corpus/csv_tables/beads.csv"
cp "$beads/template_transparent_bead_rOut10_rIn6.csv" "$corpus/csv_tables/matrix.csv"
# Rows 2..40 of the bead truth, converted (frames 0-based where the format counts from 0).
rows() { sed -n 2,40p "$truth"; }
rows | awk -F, 'BEGIN{print "frame,x,y,class,score"} {print $1-1","$3","$4","$5",0.9"}' \
    >"$corpus/csv_tables/detections.csv"
rows | awk -F, 'BEGIN{print "frame,track_id,x,y,vx,vy"} {print $1-1","$2","$3","$4","$6","$7}' \
    >"$corpus/csv_tables/truth.csv"
rows | awk -F, 'BEGIN{print "frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err"}
    {print $1-1","$2","$3","$4","$6","$7",,,,,"}' >"$corpus/csv_tables/tracks.csv"
rows | awk -F, 'BEGIN{print "frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err,class,motion_state,spread_px"}
    {split("resting rolling saltating unknown", s, " ");
     print $1-1","$2","$3","$4","$6","$7",0,0,0,0,-1.5,"$5","s[$8+1]",0.5"}' \
    >"$corpus/csv_tables/tracks-states.csv"

# --- TracTrac text: _track.txt, _par.txt; BeadTracking sequence_param.txt ------------------
{
    printf '# TracTrac v3.0 (sillage 0.1.0) \n'
    printf "#  Parameters: {'peak_th': 0.02, 'motion_av': 10}\n"
    printf '#  Frame ID x y Vx Vy Ax Ay Vx(prediction) Vy(prediction) Error(prediction)\n'
    rows | awk -F, '{printf "%d %d %.3f %.3f %.5f %.5f 0.0000 0.0000 0.0000 0.0000 -1.500\n",
        $1-1, $2, $3, $4, $6, $7}'
} >"$corpus/tractrac_text/seq_track.txt"
cp "$beads/sequence_param.txt" "$corpus/tractrac_text/sequence_param.txt"
cat >"$corpus/tractrac_text/seq_par.txt" <<'EOF'
# TracTrac parameters
vid_loop 2
ROIxmin 0
ROIymin 0
ROIxmax 512
BG 1
BG_speed 0.01
noise 1
noise_size 3
peak_th 0.02
peak_neigh 1
peak_conv 1
peak_conv_size 2
peak_subpix 1
peak_minima 0
motion 1
motion_av 10
motion_it 0
filter 1
filter_std 1.5
filter_time 1
EOF

# --- Images: crops of the bedload frames and mask, PETS JPEG headers -----------------------
python3 - "$beads" "$data/pets09_s2l1/img1/000001.jpg" "$corpus/frame_decode" <<'EOF'
import struct, sys, zlib

beads, jpeg_path, out = sys.argv[1], sys.argv[2], sys.argv[3]

def ifd_tags(data):
    """The first IFD of a little-endian TIFF as {tag: (type, count, value or offset)}."""
    assert data[:2] == b"II"
    offset = struct.unpack("<I", data[4:8])[0]
    n = struct.unpack("<H", data[offset:offset + 2])[0]
    tags = {}
    for i in range(n):
        tag, kind, count, value = struct.unpack("<HHII", data[offset + 2 + 12 * i:offset + 14 + 12 * i])
        tags[tag] = (kind, count, value)
    return tags

def u32_array(data, kind, count, value):
    if count == 1:
        return [value]
    fmt = "<%d%s" % (count, "I" if kind == 4 else "H")
    return list(struct.unpack(fmt, data[value:value + struct.calcsize(fmt)]))

def tiff(width, height, strips, tags, big_endian=False, rows_per_strip=None):
    """A one-page TIFF: `strips` (bytes each) then the IFD; `tags` is [(tag, type, values)]."""
    e = ">" if big_endian else "<"
    body = bytearray(b"MM\x00*" if big_endian else b"II*\x00") + b"\0\0\0\0"
    offsets = []
    for strip in strips:
        offsets.append(len(body))
        body += strip
    if len(body) % 2:
        body += b"\0"
    rows = rows_per_strip or height
    entries = [(256, 4, [width]), (257, 4, [height]), (278, 4, [rows]),
               (273, 4, offsets), (279, 4, [len(s) for s in strips])] + tags
    entries.sort()
    extra = bytearray()
    ifd_offset = len(body)
    extra_offset = ifd_offset + 2 + 12 * len(entries) + 4
    ifd = bytearray(struct.pack(e + "H", len(entries)))
    sizes = {3: ("H", 2), 4: ("I", 4), 5: ("II", 8), 11: ("f", 4), 12: ("d", 8)}
    for tag, kind, values in entries:
        code, size = sizes[kind]
        packed = b"".join(struct.pack(e + code, *(v if isinstance(v, tuple) else (v,))) for v in values)
        if len(packed) <= 4:
            ifd += struct.pack(e + "HHI", tag, kind, len(values)) + packed.ljust(4, b"\0")
        else:
            ifd += struct.pack(e + "HHII", tag, kind, len(values), extra_offset + len(extra)) + packed
            extra += packed
    ifd += b"\0\0\0\0"
    body[4:8] = struct.pack(e + "I", ifd_offset)
    return bytes(body + ifd + extra)

def packbits(data):
    out = bytearray()
    for i in range(0, len(data), 128):
        chunk = data[i:i + 128]
        out.append(len(chunk) - 1)
        out += chunk
    return bytes(out)

# A 32 x 32 crop of a bedload frame (8-bit grey, one uncompressed strip).
frame = open(beads + "/images/BaumerBim10MegaAmont0507Image72040.tif", "rb").read()
tags = ifd_tags(frame)
width = tags[256][2]
start = tags[273][2]
x0, y0, size = 600, 150, 32
crop = bytearray()
for y in range(y0, y0 + size):
    row = start + y * width + x0
    crop += frame[row:row + size]
crop = bytes(crop)
grey = [(262, 3, [1]), (277, 3, [1])]
def write(name, data):
    open(out + "/" + name, "wb").write(data)
write("grey8.tif", tiff(size, size, [crop], [(258, 3, [8]), (259, 3, [1])] + grey))
write("grey8-be.tif", tiff(size, size, [crop], [(258, 3, [8]), (259, 3, [1])] + grey, big_endian=True))
write("grey8-strips.tif", tiff(size, size, [crop[:16 * size], crop[16 * size:]],
                               [(258, 3, [8]), (259, 3, [1])] + grey, rows_per_strip=16))
write("grey8-packbits.tif", tiff(size, size, [packbits(crop)], [(258, 3, [8]), (259, 3, [32773])] + grey))
write("grey8-deflate.tif", tiff(size, size, [zlib.compress(crop)], [(258, 3, [8]), (259, 3, [8])] + grey))
grey16 = b"".join(struct.pack("<H", v * 257) for v in crop)
write("grey16.tif", tiff(size, size, [grey16], [(258, 3, [16]), (259, 3, [1])] + grey))
grey32f = b"".join(struct.pack("<f", v / 255) for v in crop)
write("grey32f.tif", tiff(size, size, [grey32f], [(258, 3, [32]), (259, 3, [1]), (339, 3, [3])] + grey))
rgb = bytes(v for p in crop for v in (p, p // 2, 255 - p))
write("rgb8.tif", tiff(size, size, [rgb], [(258, 3, [8, 8, 8]), (259, 3, [1]), (262, 3, [2]), (277, 3, [3])]))

# The flume-base mask (CCITT modified Huffman, 6-row strips) cut to two strips of 12 rows.
mask = open(beads + "/sequence_base_mask.tif", "rb").read()
tags = ifd_tags(mask)
offsets = u32_array(mask, *tags[273])
counts = u32_array(mask, *tags[279])
mask_tags = [(258, 3, [1]), (259, 3, [2]), (262, 3, [0]), (277, 3, [1])]
for first in (0, 26, 50):
    strips = [mask[offsets[s]:offsets[s] + counts[s]] for s in (first, first + 1)]
    write("mask-ccitt-%02d.tif" % first,
          tiff(tags[256][2], 12, strips, mask_tags, rows_per_strip=tags[278][2]))

# PNGs of the crop: grey 8/16-bit, grey + alpha, RGB, RGBA, palette.
def png(width, height, depth, colour, rows, palette=None):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    header = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    raw = b"".join(b"\0" + row for row in rows)
    chunks = chunk(b"IHDR", header)
    if palette:
        chunks += chunk(b"PLTE", palette)
    return b"\x89PNG\r\n\x1a\n" + chunks + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
lines = [crop[y * size:(y + 1) * size] for y in range(size)]
write("grey8.png", png(size, size, 8, 0, lines))
write("grey16.png", png(size, size, 16, 0, [b"".join(struct.pack(">H", v * 257) for v in l) for l in lines]))
write("greya8.png", png(size, size, 8, 4, [bytes(v for p in l for v in (p, 255)) for l in lines]))
write("rgb8.png", png(size, size, 8, 2, [bytes(v for p in l for v in (p, p // 2, 255 - p)) for l in lines]))
write("rgba8.png", png(size, size, 8, 6, [bytes(v for p in l for v in (p, p, p, 128)) for l in lines]))
write("palette.png", png(size, size, 8, 3, [bytes(p // 16 for p in l) for l in lines],
                         palette=bytes(v for i in range(16) for v in (16 * i, 16 * i, 255 - 16 * i))))

# BMPs of the crop (the format of many PIV cameras): 8-bit with a grey palette, 24-bit BGR,
# rows bottom-up, each padded to 4 bytes.
def bmp(width, height, bpp, rows, palette=b""):
    pad = b"\0" * (-len(rows[0]) % 4)
    pixels = b"".join(row + pad for row in reversed(rows))
    offset = 14 + 40 + len(palette)
    info = struct.pack("<IiiHHIIiiII", 40, width, height, 1, bpp, 0, len(pixels), 2835, 2835,
                       len(palette) // 4, 0)
    header = struct.pack("<IHHI", offset + len(pixels), 0, 0, offset)
    return b"BM" + header + info + palette + pixels
write("grey8.bmp", bmp(size, size, 8, lines, bytes(v for i in range(256) for v in (i, i, i, 0))))
write("bgr24.bmp", bmp(size, size, 24,
                      [bytes(v for p in l for v in (255 - p, p // 2, p)) for l in lines]))

# A PETS 2009 frame's JPEG headers with its frame size set to 16 x 16 or 32 x 32, the start of
# its entropy-coded data, then the end marker: the decoder reads the first 16 x 16 blocks.
jpeg = open(jpeg_path, "rb").read()
i = 2
while True:
    marker = jpeg[i + 1]
    length = struct.unpack(">H", jpeg[i + 2:i + 4])[0]
    if marker in (0xC0, 0xC1, 0xC2):
        sof = i
    if marker == 0xDA:
        scan = i + 2 + length
        break
    i += 2 + length
for side, keep in ((16, 400), (32, 1500)):
    data = bytearray(jpeg[:scan + keep])
    data[sof + 5:sof + 9] = struct.pack(">HH", side, side)
    while data[-1] == 0xFF:
        data.pop()
    write("pets-%d.jpg" % side, bytes(data) + b"\xff\xd9")
EOF

# --- Parquet track tables, uncompressed PLAIN pages, from the bead truth --------------------
python3 - "$truth" "$corpus/parquet_tracks" <<'EOF'
import struct, sys

out = sys.argv[2]
# Rows 2..40 of the bead truth, as `rows` above.
records = [line.strip().split(",") for line in open(sys.argv[1]).readlines()[1:40] if line.strip()]

def varint(n):
    b = bytearray()
    while True:
        if n < 0x80:
            b.append(n)
            return bytes(b)
        b.append(n & 0x7F | 0x80)
        n >>= 7

def zigzag(n):
    return varint((n << 1) ^ (n >> 63))

class Struct:
    """Thrift compact protocol struct writer."""
    def __init__(self):
        self.b = bytearray()
        self.last = 0
    def header(self, fid, kind):
        delta = fid - self.last
        if 0 < delta <= 15:
            self.b.append(delta << 4 | kind)
        else:
            self.b.append(kind)
            self.b += zigzag(fid)
        self.last = fid
    def i32(self, fid, v):
        self.header(fid, 5); self.b += zigzag(v); return self
    def i64(self, fid, v):
        self.header(fid, 6); self.b += zigzag(v); return self
    def binary(self, fid, v):
        self.header(fid, 8); self.b += varint(len(v)) + v; return self
    def struct(self, fid, s):
        self.header(fid, 12); self.b += s.end(); return self
    def list(self, fid, kind, items):
        self.header(fid, 9)
        self.b.append(len(items) << 4 | kind if len(items) < 15 else 0xF0 | kind)
        if len(items) >= 15:
            self.b += varint(len(items))
        for item in items:
            if kind == 5:
                self.b += zigzag(item)
            elif kind == 8:
                self.b += varint(len(item)) + item
            else:
                self.b += item.end()
        return self
    def end(self):
        return bytes(self.b) + b"\0"

INT64, DOUBLE, BYTE_ARRAY = 2, 5, 6
def write(name, columns):
    """columns: [(name, physical type, optional?, values)] -> a one-row-group Parquet file."""
    n = len(columns[0][3])
    body = bytearray(b"PAR1")
    chunks = []
    for cname, ptype, optional, values in columns:
        if ptype == INT64:
            data = b"".join(struct.pack("<q", v) for v in values)
        elif ptype == DOUBLE:
            data = b"".join(struct.pack("<d", v) for v in values if v is not None)
        else:
            data = b"".join(struct.pack("<I", len(v)) + v for v in values)
        if optional:
            # Definition levels: RLE/bit-packed hybrid, one bit-packed run, length-prefixed.
            bits = [0 if v is None else 1 for v in values]
            groups = (n + 7) // 8
            packed = bytearray(varint(groups << 1 | 1))
            for g in range(groups):
                byte = 0
                for k, bit in enumerate(bits[8 * g:8 * g + 8]):
                    byte |= bit << k
                packed.append(byte)
            data = struct.pack("<I", len(packed)) + bytes(packed) + data
        page_header = Struct().i32(1, 0).i32(2, len(data)).i32(3, len(data)).struct(
            5, Struct().i32(1, n).i32(2, 0).i32(3, 3).i32(4, 3)).end()
        offset = len(body)
        body += page_header + data
        size = len(page_header) + len(data)
        meta = (Struct().i32(1, ptype).list(2, 5, [0, 3]).list(3, 8, [cname.encode()])
                .i32(4, 0).i64(5, n).i64(6, size).i64(7, size).i64(9, offset))
        chunks.append((Struct().i64(2, offset).struct(3, meta), size))
    schema = [Struct().binary(4, b"schema").i32(5, len(columns))]
    for cname, ptype, optional, values in columns:
        element = Struct().i32(1, ptype).i32(3, 1 if optional else 0).binary(4, cname.encode())
        if ptype == BYTE_ARRAY:
            element.i32(6, 0)  # converted type UTF8
        schema.append(element)
    row_group = (Struct().list(1, 12, [c for c, _ in chunks]).i64(2, sum(s for _, s in chunks))
                 .i64(3, n))
    footer = (Struct().i32(1, 1).list(2, 12, schema).i64(3, n).list(4, 12, [row_group])
              .binary(6, b"sillage seed.sh").end())
    body += footer + struct.pack("<I", len(footer)) + b"PAR1"
    open(out + "/" + name, "wb").write(bytes(body))

frame = [int(r[0]) - 1 for r in records]
particle = [int(r[1]) for r in records]
x = [float(r[2]) for r in records]
y = [float(r[3]) for r in records]
vx = [float(r[5]) for r in records]
vy = [float(r[6]) for r in records]
none = [None] * len(records)
columns = [("frame", INT64, False, frame), ("particle", INT64, False, particle),
           ("x", DOUBLE, False, x), ("y", DOUBLE, False, y),
           ("vx", DOUBLE, True, vx), ("vy", DOUBLE, True, vy)] + [
           (c, DOUBLE, True, none) for c in ("ax", "ay", "vx_pred", "vy_pred", "log_err")]
write("tracks.parquet", columns)
states = ["resting", "rolling", "saltating", "unknown"]
write("tracks-states.parquet", columns + [
    ("class", INT64, False, [int(r[4]) for r in records]),
    ("motion_state", BYTE_ARRAY, False, [states[int(r[7])].encode() for r in records]),
    ("spread_px", DOUBLE, True, [0.5] * len(records))])
write("tracks-short.parquet", [(c, t, o, v[:3]) for c, t, o, v in columns[:4]])
EOF

# --- TOML settings: selector byte, file, NUL, `--set` lines (see fuzz_targets/toml_config.rs)
toml() { # toml NAME SELECTOR_BYTE (file text on stdin, overrides after a line `--`)
    local text
    text=$(cat)
    {
        printf "\\x$2"
        printf '%s\n' "${text%%$'\n'--$'\n'*}"
        if [[ $text == *$'\n'--$'\n'* ]]; then
            printf '\0%s\n' "${text#*$'\n'--$'\n'}"
        fi
    } >"$corpus/toml_config/$1"
}
toml ptv 00 <<'EOF'
training_passes = 0

[preprocess]
median = 3

[preprocess.background]
speed = 0.01

[detector]
kind = "blob"
scale_px = "auto"
neighbourhood = 1

[detector.roi]
x0 = 0
y0 = 0
x1 = 512
y1 = 512

[tracker]
kind = "ptv"
motion_av = 10
max_displacement_px = 20
--
detector.scale_px=2.5
tracker.vote_search_px=auto
EOF
toml ptv-bead 00 <<'EOF'
[detector]
kind = "bead"

[detector.params]
m_per_px = 0.0002056
black_diameter_m = 0.006
transparent_diameter_m = 0.004
transparent_threshold = 0.3

[tracker]
kind = "bedload"
--
detector.params.candidate_threshold=0.5
EOF
toml bedload 01 <<'EOF'
tracker = "mmpf_plus"
seed = 7
radius_px = [15.0, 10.0]
field_px = [1280.0, 320.0]

[smoother]
lag = 4

[smoother.emission]
speed_floor_m_per_s = 0.0013364

[smoother.emission.rolling.log_speed]
mean = -4.383
sd = 1.6
--
likelihood.gamma=0.7
tracker=pf
EOF
toml bead 02 <<'EOF'
m_per_px = 0.0002056
black_diameter_m = 0.006
transparent_diameter_m = 0.004
ring_inner_ratio = 0.6
black_threshold = 0.25
smoothing_passes = 2
dark_rejection_ratio = 0.5
--
transparent_threshold=0.3
EOF
toml immpf 03 <<'EOF'
[tracker]
models = ["cv", "ca", "mp"]
pos_noise_px = 2.0
death_frames = 10
confirm_frames = 3

[motion_detector]
group_aspect = 0.55

[motion_detector.detector]
open_radius_px = 1
min_blob_px = 40
--
tracker.filter.particles=100
EOF
toml siftpf 04 <<'EOF'
[tracker]
selection = "all"

[motion_detector]
open_radius_px = 1
close_radius_px = 2
min_component_px = 20
--
motion_detector.group_aspect=1.0
EOF
toml motion 05 <<'EOF'
open_radius_px = 1
close_radius_px = 2
min_component_px = 20
merge_gap_px = 3
min_blob_px = 40
group_aspect = 0.55
person_aspect = 0.4

[mixture]
bootstrap_frames = 20
--
mixture.bootstrap_frames=5
EOF
toml ground-plane 06 <<'EOF'
[homography]
image_from_ground = [[30.0, 0.0, 100.0], [0.0, -30.0, 400.0], [0.0, 0.0, 1.0]]

[pedestrian]
height_m = 1.74
width_m = 0.58

[fit]
source = "pets09_s2l1/gt/gt.txt"
pairs = 120
EOF

# --- Tuning server requests ------------------------------------------------------------------
printf 'GET / HTTP/1.1\r\nHost: localhost:8080\r\nAccept: text/html\r\n\r\n' \
    >"$corpus/tune_http/get-page"
printf 'GET /frame/3?t=1 HTTP/1.1\r\nHost: localhost\r\n\r\n' >"$corpus/tune_http/get-frame"
body='{"scale_px": 2.5, "threshold": {"auto": {"std_factor": 3.0}}, "frame": 0}'
printf 'POST /api/detect HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\nContent-Length: %d\r\n\r\n%s' \
    "${#body}" "$body" >"$corpus/tune_http/post-detect"
printf 'POST /api/save HTTP/1.1\r\ncontent-length: 2\r\n\r\n{}' >"$corpus/tune_http/post-save"

du -sh "$corpus"/* | sed "s|$corpus/||"
