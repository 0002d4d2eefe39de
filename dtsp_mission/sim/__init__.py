"""The simulated fixed-wing vehicle: its flight (:mod:`.flight`), its MAVLink side on MAVSDK's
server plugins (:mod:`.vehicle`), a fault-injecting UDP proxy (:mod:`.fault_proxy`), and the
pre-flight check that flies a mission and measures it (:mod:`.fly`)."""
