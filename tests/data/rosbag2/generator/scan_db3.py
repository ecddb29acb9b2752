#!/usr/bin/env python3
"""Writes the lidar fixture room_b.db3 (rosbag2 SQLite3, Humble schema: topics
with offered_qos_profiles) with Python's sqlite3 from the CDR payloads
scan_gen.mjs dumps (room_b_payloads.tsv: topic, type, receive time [ns], hex
CDR per line), then deletes the dump.
usage: scan_db3.py SCAN_FIXTURE_DIR"""
import os
import sqlite3
import sys

out = sys.argv[1]
tsv = os.path.join(out, "room_b_payloads.tsv")
rows = [l.rstrip("\n").split("\t") for l in open(tsv) if l.strip()]
topics = []
for topic, typ, _, _ in rows:
    if (topic, typ) not in topics:
        topics.append((topic, typ))
path = os.path.join(out, "room_b.db3")
if os.path.exists(path):
    os.remove(path)
db = sqlite3.connect(path)
db.execute("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
           "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)")
db.execute("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
           "timestamp INTEGER NOT NULL, data BLOB NOT NULL)")
db.execute("CREATE INDEX timestamp_idx ON messages (timestamp ASC)")
for i, (topic, typ) in enumerate(topics, 1):
    db.execute("INSERT INTO topics VALUES (?, ?, ?, ?, ?)", (i, topic, typ, "cdr", ""))
ids = {t: i for i, (t, _) in enumerate(topics, 1)}
db.executemany("INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)",
               [(ids[t], int(ns), bytes.fromhex(h)) for t, _, ns, h in rows])
db.commit()
db.execute("VACUUM")
db.close()
os.remove(tsv)
