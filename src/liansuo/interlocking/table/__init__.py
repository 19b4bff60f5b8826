"""The interlocking table (联锁表), derived offline from the station: routes, conflicts, flank, overlaps; its text,
signed, JSON Schema and xlsx forms, liansuo table."""
