//! NMEA 0183 GNSS logs (being written: see issue #3).
