"""A simulation on record: the recorder, the recording file and its schema, the replayer."""
