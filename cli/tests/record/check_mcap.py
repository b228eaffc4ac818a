"""Reads an MCAP file written by `limber record` with the reference reader (the `mcap`
package, CRCs checked) and decodes limber's messages from their schemas alone (the layout
manifest's structs: fields with offsets, sizes and types), without limber's code.

Prints one JSON object: per topic, the schema, the count, the decoded header sequence
numbers (states), the decoded messages' chosen fields."""

import json
import struct
import sys

from mcap.reader import make_reader

SCALARS = {
    "u8": "B", "u16": "H", "u32": "I", "u64": "Q",
    "i8": "b", "i16": "h", "i32": "i", "i64": "q",
    "f32": "f", "f64": "d",
}


def decode(structs, name, data, base=0):
    """The struct `name` at `base` of `data`, as a dict."""
    s = structs[name]
    out = {}
    for f in s["fields"]:
        ty, n, off = f["type"], f["array_len"], base + f["offset"]
        count = max(n, 1)
        if ty in SCALARS:
            vals = list(struct.unpack_from("<%d%s" % (count, SCALARS[ty]), data, off))
        else:
            size = structs[ty]["size"]
            vals = [decode(structs, ty, data, off + i * size) for i in range(count)]
        out[f["name"]] = vals if n else vals[0]
    return out


def main(path):
    topics = {}
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        for schema, channel, message in reader.iter_messages():
            t = topics.setdefault(channel.topic, {
                "schema": schema.name if schema else "",
                "encoding": channel.message_encoding,
                "count": 0,
                "seqs": [],
                "decoded": [],
            })
            t["count"] += 1
            if schema.encoding == "limber-layout":
                layout = json.loads(schema.data)
                structs = {s["name"]: s for s in layout["structs"]}
                root = structs[layout["root"]]
                assert len(message.data) == root["size"], (channel.topic, len(message.data))
                d = decode(structs, layout["root"], message.data)
                if "header" in d:
                    t["seqs"].append(d["header"]["seq"])
                if layout["root"] == "ActArrayData":
                    t["decoded"].append([a["position"] for a in d["actuators"][: d["actuators_count"]]])
                elif layout["root"] == "OutcomeMsg":
                    t["decoded"].append(d["status"])
                elif layout["root"] == "DriverStats":
                    t["decoded"].append(bytes(d["driver"]).split(b"\0")[0].decode())
            elif channel.message_encoding == "json":
                t["decoded"].append(json.loads(message.data))
    print(json.dumps({
        "message_count": summary.statistics.message_count,
        "channels": len(summary.channels),
        "topics": topics,
    }))


if __name__ == "__main__":
    main(sys.argv[1])
