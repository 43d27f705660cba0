"""RPC III time-history files written and read with numpy alone, from the format description
(not through dydp): 512-byte header blocks of 128-byte records (32-byte key, 96-byte value),
FORMAT, NUM_HEADER_BLOCKS and NUM_PARAMS first; data group by group, channel by channel inside
a group, little-endian; SHORT_INTEGER samples times SCALE.CHAN_n, or FLOATING_POINT."""
import numpy as np


def header_records(channels, dt, data_type, pts_per_frame, frames_per_group, frames, scales):
    records = [
        ("FORMAT", "BINARY_IEEE_LITTLE_END"), ("NUM_HEADER_BLOCKS", ""), ("NUM_PARAMS", ""),
        ("FILE_TYPE", "TIME_HISTORY"), ("TIME_TYPE", "DRIVE"), ("DELTA_T", repr(dt)),
        ("CHANNELS", str(len(channels))), ("DATA_TYPE", data_type),
        ("PTS_PER_FRAME", str(pts_per_frame)), ("PTS_PER_GROUP", str(pts_per_frame * frames_per_group)),
        ("FRAMES", str(frames)), ("REPEATS", "1"), ("HALF_FRAMES", "0"), ("INT_FULL_SCALE", "32768"),
    ]
    for c, (desc, units, _) in enumerate(channels, start=1):
        records += [(f"DESC.CHAN_{c}", desc), (f"UNITS.CHAN_{c}", units), (f"MAP.CHAN_{c}", str(c))]
        if data_type == "SHORT_INTEGER":
            records.append((f"SCALE.CHAN_{c}", repr(scales[c - 1])))
    return records


def encode(records, num_params=None, num_blocks=None):
    blocks = num_blocks or -(-len(records) // 4)
    records = list(records)
    for k, (key, value) in enumerate(records):
        if key == "NUM_HEADER_BLOCKS" and value == "":
            records[k] = (key, str(blocks))
        if key == "NUM_PARAMS" and value == "":
            records[k] = (key, str(num_params or len(records)))
    out = bytearray()
    for key, value in records:
        out += key.encode().ljust(32, b"\0")[:32] + value.encode().ljust(96, b"\0")[:96]
    return bytes(out.ljust(512 * blocks, b"\0"))


def channel_data(channels, data_type, pts_per_frame, frames_per_group, pad_value=0.0):
    """The samples as stored (padded) and as the reader decodes them (first n_stored points)."""
    n = len(channels[0][2])
    frames = -(-n // pts_per_frame)
    per_group = pts_per_frame * frames_per_group
    groups = -(-frames * pts_per_frame // per_group)
    total = groups * per_group
    stored, decoded, scales = [], [], []
    for _, _, values in channels:
        v = np.full(total, pad_value, dtype=float)
        v[:n] = values
        if data_type == "SHORT_INTEGER":
            scale = float(np.abs(values).max()) / 32000.0
            q = np.round(v / scale).astype("<i2")
            stored.append(q)
            decoded.append(q[: frames * pts_per_frame].astype(float) * scale)
            scales.append(scale)
        else:
            q = v.astype("<f4")
            stored.append(q)
            decoded.append(q[: frames * pts_per_frame].astype(float))
            scales.append(1.0)
    data = bytearray()
    for g in range(groups):
        for q in stored:
            data += q[g * per_group:(g + 1) * per_group].tobytes()
    return bytes(data), decoded, scales, frames


def write(path, channels, dt, data_type="FLOATING_POINT", pts_per_frame=64, frames_per_group=1,
          edit=None):
    """Writes channels [(description, units, values)] sampled every dt. edit(records) may change
    the header records before they are encoded. Returns the decoded samples per channel (what a
    reader must find, the last frame's padding included)."""
    data, decoded, scales, frames = channel_data(channels, data_type, pts_per_frame, frames_per_group)
    records = header_records(channels, dt, data_type, pts_per_frame, frames_per_group, frames, scales)
    if edit:
        records = edit(records)
    with open(path, "wb") as f:
        f.write(encode(records) + data)
    return decoded


def read(path):
    """(header dict, {description: samples}) of a little-endian time-history file."""
    raw = open(path, "rb").read()

    def record(k):
        chunk = raw[k * 128:(k + 1) * 128]
        return chunk[:32].split(b"\0")[0].decode().strip(), chunk[32:].split(b"\0")[0].decode().strip()

    assert [record(k)[0] for k in range(3)] == ["FORMAT", "NUM_HEADER_BLOCKS", "NUM_PARAMS"]
    header = dict(record(k) for k in range(int(record(2)[1])))
    blocks = int(header["NUM_HEADER_BLOCKS"])
    nch, ppf = int(header["CHANNELS"]), int(header["PTS_PER_FRAME"])
    ppg, frames = int(header["PTS_PER_GROUP"]), int(header["FRAMES"])
    short = header["DATA_TYPE"] == "SHORT_INTEGER"
    dtype = np.dtype("<i2" if short else "<f4")
    points = frames * ppf
    groups = -(-points // ppg)
    data = np.frombuffer(raw, dtype=dtype, offset=512 * blocks, count=groups * ppg * nch)
    data = data.reshape(groups, nch, ppg).transpose(1, 0, 2).reshape(nch, groups * ppg)[:, :points]
    out = {}
    for c in range(nch):
        scale = float(header[f"SCALE.CHAN_{c + 1}"]) if short else 1.0
        out[header[f"DESC.CHAN_{c + 1}"]] = data[c].astype(float) * scale
    return header, out
