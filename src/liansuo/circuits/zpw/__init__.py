"""The ZPW-2000A jointless track circuit: the line model, its ends, the adjustment table, the figures of a station,
the check against the capacitor-fault article, liansuo zpw."""
