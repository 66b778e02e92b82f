"""The decision process: episodes, the engines (one world and a batch), observations, slot
features, rewards."""
