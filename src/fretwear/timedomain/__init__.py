"""timedomain"""
