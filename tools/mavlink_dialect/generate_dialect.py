#!/usr/bin/env python3
"""Writes services/autopilot/mavlink/dialect.def, airseg's compact table of ArduPilot's MAVLink dialect, from
the MAVLink message definition XML (ardupilotmega.xml and every file it includes, recursively).

    python3 tools/mavlink_dialect/generate_dialect.py DEFINITIONS_DIR > services/autopilot/mavlink/dialect.def

The output lists each message once, ordered by id, with its fields in XML declaration order (type, name,
array length) and the XML's <extensions/> marker; wire order, lengths and CRC_EXTRA are derived from it by
the codec (layout.hpp), not written here. The build reads only the generated file, never the XML.
"""
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT_FILE = "ardupilotmega.xml"
TYPES = {"char", "uint8_t", "int8_t", "uint16_t", "int16_t", "uint32_t", "int32_t", "uint64_t", "int64_t",
         "float", "double"}
FIELD_TYPE = re.compile(r"^([a-z0-9_]+?)(?:\[(\d+)\])?$")


def load(directory, name, seen, files):
    """Collects the files in include order (depth first), each once."""
    if name in seen:
        return
    seen.add(name)
    root = ET.parse(directory / name).getroot()
    for include in root.findall("include"):
        load(directory, include.text.strip(), seen, files)
    files.append((name, root))


def fields_of(message, source):
    out = []
    for child in message:
        if child.tag == "extensions":
            out.append(None)
            continue
        if child.tag != "field":
            continue
        match = FIELD_TYPE.match(child.get("type"))
        if not match:
            sys.exit(f"{source}: {message.get('name')}.{child.get('name')}: unreadable type {child.get('type')}")
        base, length = match.group(1), int(match.group(2) or 0)
        if base == "uint8_t_mavlink_version":
            base = "uint8_t"  # hashed as uint8_t by CRC_EXTRA; the generated code treats it as one
        if base not in TYPES or not 0 <= length < 256:
            sys.exit(f"{source}: {message.get('name')}.{child.get('name')}: unsupported type {child.get('type')}")
        out.append((base, child.get("name"), length))
    return out


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    directory = Path(sys.argv[1])
    files = []
    load(directory, ROOT_FILE, set(), files)
    messages = {}
    for source, root in files:
        for message in root.iter("message"):
            msgid, name = int(message.get("id")), message.get("name")
            if msgid in messages:
                sys.exit(f"{source}: message id {msgid} ({name}) is also {messages[msgid][0]}")
            messages[msgid] = (name, source, fields_of(message, source))
    names = [m[0] for m in messages.values()]
    if len(set(names)) != len(names):
        sys.exit("a message name is used twice")

    out = sys.stdout
    out.write("// ArduPilot's MAVLink dialect, ordered by id: every message of ardupilotmega.xml and of the files it\n")
    out.write("// includes (" + ", ".join(name for name, _ in files[:4]) + ",\n")
    out.write("// " + ", ".join(name for name, _ in files[4:]) + ").\n")
    out.write("// GENERATED, do not edit: python3 tools/mavlink_dialect/generate_dialect.py DEFINITIONS_DIR >\n")
    out.write("//   services/autopilot/mavlink/dialect.def   (DEFINITIONS_DIR: the MAVLink message definition XML)\n")
    out.write("//\n")
    out.write("// An X-macro list like messages.def, included by dialect_table.cpp with these macros defined:\n")
    out.write("//   AIRSEG_MAVLINK_DIALECT_MESSAGE(id, \"NAME\")       starts a message\n")
    out.write("//   AIRSEG_MAVLINK_DIALECT_FIELD(type, \"name\", n)    a field in XML order; n: array length, 0 a scalar\n")
    out.write("//   AIRSEG_MAVLINK_DIALECT_EXTENSIONS()              the XML's <extensions/>: later fields are extensions\n")
    out.write("//   AIRSEG_MAVLINK_DIALECT_END()                     ends the message\n")
    out.write("// It undefines all four at its end. uint8_t_mavlink_version is written as uint8_t (CRC_EXTRA hashes\n")
    out.write("// it so). Wire order, lengths and CRC_EXTRA are derived by layout.hpp.\n")
    out.write("// clang-format off\n")
    for msgid in sorted(messages):
        name, source, fields = messages[msgid]
        out.write(f"\nAIRSEG_MAVLINK_DIALECT_MESSAGE({msgid}, \"{name}\")\n")
        for field in fields:
            if field is None:
                out.write("AIRSEG_MAVLINK_DIALECT_EXTENSIONS()\n")
            else:
                out.write(f"AIRSEG_MAVLINK_DIALECT_FIELD({field[0]}, \"{field[1]}\", {field[2]})\n")
        out.write("AIRSEG_MAVLINK_DIALECT_END()\n")
    out.write("\n// clang-format on\n")
    for macro in ("MESSAGE", "FIELD", "EXTENSIONS", "END"):
        out.write(f"#undef AIRSEG_MAVLINK_DIALECT_{macro}\n")


if __name__ == "__main__":
    main()
