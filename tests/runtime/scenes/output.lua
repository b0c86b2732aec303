-- output.lua PATH: writes "output\n" to PATH through io.output.
io.output(arg[1])
io.write("output\n")
io.close()
print("output done")
