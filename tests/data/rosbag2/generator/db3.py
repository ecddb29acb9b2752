#!/usr/bin/env python3
"""Writes rosbag2 SQLite3 fixtures with Python's sqlite3 from the CDR
payloads gen.mjs dumps (run1_head_payloads.tsv: topic, type, receive time
[ns], hex CDR per line). Two schema generations, as rosbag2 writes them:
  humble/  (folder with metadata.yaml): topics with offered_qos_profiles
  jazzy.db3 (single file): topics with type_description_hash, plus the
            schema and metadata tables of newer distributions
usage: db3.py FIXTURE_DIR"""
import os
import sqlite3
import sys

out = sys.argv[1]
rows = [l.rstrip("\n").split("\t") for l in open(os.path.join(out, "run1_head_payloads.tsv")) if l.strip()]
topics = []
for topic, typ, _, _ in rows:
    if (topic, typ) not in topics:
        topics.append((topic, typ))


def write(path, jazzy):
    if os.path.exists(path):
        os.remove(path)
    db = sqlite3.connect(path)
    extra = ", offered_qos_profiles TEXT NOT NULL" + (", type_description_hash TEXT NOT NULL" if jazzy else "")
    db.execute("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
               "serialization_format TEXT NOT NULL" + extra + ")")
    db.execute("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
               "timestamp INTEGER NOT NULL, data BLOB NOT NULL)")
    db.execute("CREATE INDEX timestamp_idx ON messages (timestamp ASC)")
    if jazzy:
        db.execute("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)")
        db.execute("INSERT INTO schema VALUES (4, 'jazzy')")
        db.execute("CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL)")
    for i, (topic, typ) in enumerate(topics, 1):
        vals = [i, topic, typ, "cdr", ""] + (["RIHS01_" + "0" * 64] if jazzy else [])
        db.execute("INSERT INTO topics VALUES (" + ",".join("?" * len(vals)) + ")", vals)
    ids = {t: i for i, (t, _) in enumerate(topics, 1)}
    db.executemany("INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)",
                   [(ids[t], int(ns), bytes.fromhex(h)) for t, _, ns, h in rows])
    db.commit()
    db.execute("VACUUM")
    db.close()


os.makedirs(os.path.join(out, "humble"), exist_ok=True)
write(os.path.join(out, "humble", "run1_head_0.db3"), False)
with open(os.path.join(out, "humble", "metadata.yaml"), "w") as f:
    f.write("rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
            "  relative_file_paths:\n    - run1_head_0.db3\n  message_count: %d\n" % len(rows))
write(os.path.join(out, "jazzy.db3"), True)
os.remove(os.path.join(out, "run1_head_payloads.tsv"))
