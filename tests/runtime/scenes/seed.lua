-- seed.lua: prints the scene seed.
print("seed", outcrop.seed, math.type(outcrop.seed))
