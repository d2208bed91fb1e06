"""Flight logs in PX4's ULog format: the format (ulog_writer.py), the topics (topics.py), the logger (flight_log.py)
and how `serve` and `Sim` attach it to a vehicle node and serve its files (serving.py)."""
