"""The sensor role: the tool is the data recorder and judges a sensor.

``session`` holds the stimulus cache the sensor cases share, ``address_change`` the guarded
change-address probe, ``exploration`` the stateful random exploration. The tool's own data
recorder (stimuli, retries, records) is :mod:`conformance.tool_recorder`, shared with the
recorder role's golden reference.
"""
