"""The shared layer every part of the simulator (and the other stages) may import: errors, atomic file writing,
option types and units. It imports nothing else of `sim`."""
